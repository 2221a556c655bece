"""What a notebook became: the graded module's source, and the summary of what ran and what did not."""

from __future__ import annotations

import re
from dataclasses import dataclass

from pydantic import BaseModel, ConfigDict, Field

from grader.submission.notebook.cells import SCRIPT_CELL


class SkippedCode(BaseModel):
    """One statement (or cell) of a notebook the grader did not run."""

    model_config = ConfigDict(extra="forbid")

    cell: int = Field(description="Position of the cell in the notebook (1 = first cell, markdown included).")
    execution_count: int | None = Field(description="The cell's In [n] number when it was saved, if any.")
    line: int = Field(description="Line within the cell where the statement starts (1-based).")
    reason: str = Field(description="What kind of statement it is, and so why it was not run.")
    code: str = Field(description="The statement's first line (shortened).")


class UnboundGlobal(BaseModel):
    """A global a graded function reads that only a skipped statement sets."""

    model_config = ConfigDict(extra="forbid")

    function: str = Field(description="The top-level function whose call reaches the name.")
    name: str = Field(description="The global name.")
    cell: int = Field(description="Cell of the (first) skipped statement that sets it.")
    line: int = Field(description="Line of that statement within its cell.")
    code: str = Field(description="That statement's first line.")
    broken_cell: bool = Field(
        default=False,
        description="The statement sits in a cell that is not valid Python (so none of it ran).",
    )

    def note(self) -> str:
        """The sentence added to the feedback of the problem named after ``function``."""
        if self.cell == SCRIPT_CELL:
            return (
                f"Your file: {self.function}() reads the global `{self.name}`, which only a skipped top-level statement sets (line {self.line}: `{self.code}`). "  # noqa: E501
                f"The grader reads a .py as the notebook it came from and runs only imports, definitions and simple constants at import, so there is no `{self.name}` when {self.function}() is called: "  # noqa: E501
                "compute it inside the function."
            )
        if self.broken_cell:
            return (
                f"Notebook: {self.function}() uses `{self.name}`, which only cell {self.cell} defines, "
                f"and that cell cannot be read (line {self.line}: `{self.code}`), so Jupyter ran none of it either: "  # noqa: E501
                "fix that cell, run it, save the notebook and submit again."
            )
        return (
            f"Notebook: {self.function}() reads the global `{self.name}`, which only a skipped top-level statement sets (cell {self.cell}, line {self.line}: `{self.code}`). "  # noqa: E501
            f"The grader runs only imports, definitions and simple constants of a notebook, so there is no `{self.name}` when {self.function}() is called: "  # noqa: E501
            "compute it inside the function."
        )


class NotebookSummary(BaseModel):
    """How a notebook became the graded module: what ran at import and what did not."""

    model_config = ConfigDict(extra="forbid")

    code_cells: int = Field(description="Code cells in the notebook.")
    kept_statements: int = Field(description="Top-level statements run at import (imports, definitions...).")
    skipped: list[SkippedCode] = Field(default_factory=list, description="Everything not run, cell by cell.")
    unbound_globals: list[UnboundGlobal] = Field(
        default_factory=list, description="Globals graded functions read that only skipped statements set."
    )
    ignored: list[str] = Field(
        default_factory=list,
        description="What of the file itself the grader ignored to read the cells (metadata that does not follow the nbformat schema, an old format version); for a .py, why its whole file ran at import.",  # noqa: E501
    )
    script: bool = Field(
        default=False,
        description="Read from a .py file (a notebook's export) by the notebook's rules: every entry's cell is 0 and its line is the file's own.",  # noqa: E501
    )

    def notes_for(self, function: str) -> list[str]:
        """The notes about globals missing for ``function`` (a problem id names its function)."""
        return [entry.note() for entry in self.unbound_globals if entry.function == function]


@dataclass(frozen=True)
class NotebookModule:
    """The graded module built from a notebook, and how it was built.

    Attributes:
        source: The module's Python source.
        summary: What ran and what was skipped (goes into the report).
        origins: For each line of ``source`` (0-based), the (cell, line in cell) it came from, if any.
        cells: Every code cell Jupyter's "Run All" would run, in order, as (cell number, its Python source
            after IPython's transformations): what a problem that runs the notebook's cells executes
            (`grader.submission.notebook.cells`). Cells of a non-Python cell magic are left out.
    """

    source: str
    summary: NotebookSummary
    origins: tuple[tuple[int, int] | None, ...] = ()
    cells: tuple[tuple[int, str], ...] = ()

    def cited(self, text: str, module_name: str) -> str:
        """``text`` with ``File ".../<module_name>", line N`` rewritten to the notebook's cell and line (a
        `.py` read as a notebook: to the file's own line; its module has the file's name, ``module_name``
        without the ``.py`` a notebook's module adds)."""
        if self.summary.script:
            module_name = module_name.removesuffix(".py")

        def replace(match: re.Match[str]) -> str:
            number = int(match.group("line"))
            origin = self.origins[number - 1] if 0 < number <= len(self.origins) else None
            if origin is None:
                return match.group(0)
            if origin[0] == SCRIPT_CELL:
                return f'File "{match.group("name")}", line {origin[1]}'
            return f'File "{match.group("name").removesuffix(".py")}", cell {origin[0]}, line {origin[1]}'

        pattern = rf'File "(?:[^"]*/)?(?P<name>{re.escape(module_name)})", line (?P<line>\d+)'
        return re.sub(pattern, replace, text)
