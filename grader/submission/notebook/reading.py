"""Read a notebook file's code cells as Jupyter does: the cells matter, odd metadata is noted and ignored."""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass
from typing import Any

from grader.submission.validation import FileVerdict

MAX_NOTEBOOK_BYTES = 20_000_000
"""Outputs (plots, rendered frames) make notebooks large; only the code cells are graded, and they are
held to the ``.py`` limit once extracted."""
MAX_CODE_CHARS = 2_000_000
"""Characters of code (all code cells together) the grader reads: twice the ``.py`` limit, as skipped
demo cells do not count towards that."""
MAX_CELLS = 10_000
"""Cells (of any kind) a notebook may have: a lab notebook has well under a hundred; millions of empty
ones would make every later step slow."""
MAX_IGNORED_DETAIL = 200
PYTHON_LANGUAGES = ("python", "ipython")


@dataclass(frozen=True)
class Cell:
    """One code cell: its position among all cells, its In [n] number and its source."""

    number: int
    execution_count: int | None
    source: str

    @property
    def label(self) -> str:
        """``code cell 7 (In [12])``, as the messages name a cell."""
        run = f" (In [{self.execution_count}])" if self.execution_count is not None else ""
        return f"code cell {self.number}{run}"


@dataclass(frozen=True)
class NotebookCells:
    """The code cells of a notebook and what of the file was ignored to read them."""

    cells: list[Cell]
    ignored: list[str]


def read_cells(data: bytes, name: str) -> NotebookCells | FileVerdict:
    """The code cells of a ``.ipynb`` file (nbformat 4, or 3 as IPython 1-3 saved it).

    Metadata that does not follow the nbformat schema (a kernelspec without ``display_name``, an unknown
    minor version, cells without ids...) is ignored and noted, as Jupyter opens such files. Only a file
    whose cells cannot be read is refused.

    Args:
        data: The file's bytes.
        name: Its file name, used in messages.

    Returns:
        The code cells (blank ones left out) and the notes, or the verdict saying why there is nothing to
        grade.
    """
    if len(data) > MAX_NOTEBOOK_BYTES:
        return FileVerdict(
            "error",
            f"{name} is {len(data):,} bytes; a notebook may be at most {MAX_NOTEBOOK_BYTES:,} bytes. "
            "Clear its outputs (Kernel > Restart & Clear Output) and submit again.",
        )
    if not data.strip():
        return FileVerdict("missing", f"{name} is empty: nothing to grade. Submit your saved notebook.")
    try:
        notebook = json.loads(data.decode("utf-8-sig"))
    except RecursionError:
        return FileVerdict(
            "error",
            f"{name} is not a readable notebook: its JSON nests too deeply for the reader. {_RESAVE}",
        )
    except (UnicodeDecodeError, json.JSONDecodeError) as error:
        detail = str(error).splitlines()[0][:MAX_IGNORED_DETAIL] if str(error) else type(error).__name__
        return FileVerdict(
            "error",
            f"{name} is not a readable notebook: it is not valid JSON ({detail}). "
            "Open it in Jupyter, save it again (File > Save) and submit the saved .ipynb, or submit your code as a .py file.",  # noqa: E501
        )
    if not isinstance(notebook, dict) or not isinstance(
        notebook.get("cells", notebook.get("worksheets")), list
    ):
        return FileVerdict(
            "error",
            f'{name} is JSON but not a Jupyter notebook (expected an object with "nbformat" and a list of "cells"). '  # noqa: E501
            "Submit the .ipynb file Jupyter saved, or your code as a .py file.",
        )
    ignored: list[str] = []
    language = _language(notebook.get("metadata"))
    if language is not None and not language.lower().startswith(PYTHON_LANGUAGES):
        return FileVerdict(
            "error",
            f"{name} is a {language} notebook; the lab is graded in Python. Submit a Python notebook.",
        )
    raw_cells = _raw_cells(notebook, ignored)
    if isinstance(raw_cells, str):
        return FileVerdict("error", f"{name} is not a readable notebook: {raw_cells}. {_RESAVE}")
    if len(raw_cells) > MAX_CELLS:
        return FileVerdict(
            "error",
            f"{name} has {len(raw_cells):,} cells; a notebook may have at most {MAX_CELLS:,}. "
            "Delete the cells that are not part of your solution (or submit your code as a .py file) and submit again.",  # noqa: E501
        )
    cells: list[Cell] = []
    for number, raw in enumerate(raw_cells, start=1):
        if not isinstance(raw, dict):
            return FileVerdict(
                "error", f"{name} is not a readable notebook: cell {number} is not an object. {_RESAVE}"
            )
        if raw.get("cell_type") != "code":
            continue
        source = raw.get("source", raw.get("input", ""))
        if isinstance(source, list) and all(isinstance(line, str) for line in source):
            source = "".join(source)
        if not isinstance(source, str):
            return FileVerdict(
                "error",
                f"{name} is not a readable notebook: the source of code cell {number} is a {type(source).__name__}, not text. "  # noqa: E501
                f"{_RESAVE}",
            )
        count = raw.get("execution_count", raw.get("prompt_number"))
        if source.strip():
            cells.append(Cell(number, count if type(count) is int else None, source))
    code_chars = sum(len(cell.source) for cell in cells)
    if code_chars > MAX_CODE_CHARS:
        return FileVerdict(
            "error",
            f"{name} holds {code_chars:,} characters of code; the grader reads at most {MAX_CODE_CHARS:,}. "
            "Remove the cells that are not part of your solution (or submit your code as a .py file) and submit again.",  # noqa: E501
        )
    if not cells:
        return FileVerdict(
            "missing",
            f"{name} has no code cells: nothing to grade. Submit the notebook with your functions in it.",
        )
    if notebook.get("nbformat") == 4:
        ignored += _schema_notes(notebook)
    return NotebookCells(cells, ignored)


_RESAVE = "Open it in Jupyter, save it again and submit the saved file, or submit your code as a .py file."


def _language(metadata: Any) -> str | None:
    if not isinstance(metadata, dict):
        return None
    for key, field in (("language_info", "name"), ("kernelspec", "language")):
        section = metadata.get(key)
        if isinstance(section, dict) and isinstance(section.get(field), str) and section[field].strip():
            return str(section[field])
    return None


def _raw_cells(notebook: dict[str, Any], ignored: list[str]) -> list[Any] | str:
    version = notebook.get("nbformat")
    if "cells" in notebook:
        if version != 4:
            ignored.append(f"the file says nbformat {version!r}; its cells were read as nbformat 4's")
        return list(notebook["cells"])
    worksheets = notebook["worksheets"]
    ignored.append(f"an nbformat {version!r} notebook (IPython 1-3); its cells were read as such")
    cells: list[Any] = []
    for worksheet in worksheets:
        if not isinstance(worksheet, dict) or not isinstance(worksheet.get("cells", []), list):
            return "a worksheet of this old-format notebook has no list of cells"
        cells += worksheet.get("cells", [])
    return cells


def _schema_notes(notebook: dict[str, Any]) -> list[str]:
    """What does not follow the nbformat 4 schema, checked on the cells' sources and the metadata only
    (outputs are not graded, and checking megabytes of them would only cost time)."""
    import nbformat

    light = dict(notebook)
    light["cells"] = [
        {**cell, "outputs": []} if isinstance(cell, dict) and isinstance(cell.get("outputs"), list) else cell
        for cell in notebook["cells"]
    ]
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            nbformat.validate(light, version=4)  # type: ignore[no-untyped-call]
    except (nbformat.ValidationError, ValueError, KeyError, TypeError, AttributeError) as error:
        detail = str(getattr(error, "message", error)).splitlines()[0][:MAX_IGNORED_DETAIL]
        return [
            f"the file does not follow the nbformat 4 schema ({detail}); "
            "as Jupyter opens it all the same, the grader read its code cells"
        ]
    return []
