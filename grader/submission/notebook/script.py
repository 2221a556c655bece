"""A `.py` read as the notebook it may have been: its cells, and IPython's lines as the exports write them.

Jupyter's "Download as Python" (``jupyter nbconvert --to script``), Colab's "Download .py" and jupytext keep a
notebook's demo and training cells as top-level statements and write IPython's lines as calls:
``%matplotlib inline`` becomes ``get_ipython().run_line_magic('matplotlib', 'inline')``, ``!pip install gym``
``get_ipython().system('pip install gym')``, ``x = !ls`` ``x = get_ipython().getoutput('ls')``, a ``%%time``
cell ``get_ipython().run_cell_magic('time', '', 'body')``. Such a file is read here into cells that the
notebook reader (`grader.submission.notebook.building`) reads by its own rules:

- **Cells.** nbconvert's ``# In[N]:`` and jupytext's / VS Code's ``# %%`` markers split the file where
  present (a marker inside a statement splits nothing); otherwise each top-level statement is its own cell,
  so a cell magic Colab wrote mid-file is read as the cell it was. A cell keeps its first line in the file
  (`ScriptCell.first_line`): whatever the report says of a line is the file's own line.
- **IPython's lines** are turned back into the ``%`` / ``!`` / ``%%`` lines the notebook had (`unexported`),
  so IPython's transformer reads them as it reads the notebook's (`grader.submission.notebook.ipython`).
- **Running it** (`NotebookModule.cells`): the cells as Jupyter's "Run All" of its notebook runs them, each
  on the file's own lines: each IPython line ``pass``, a ``%%time`` / ``%%capture`` cell's body, no other
  cell magic's body.

`defines_only` says, without the reader child, that a file's top level holds only imports, definitions, a
docstring and an ``if __name__ == "__main__":`` block: such a file is graded as it is, as it always was.

Pure, and unbounded: run on untrusted text only in the bounded reader child (`bounded.build_script`).
"""

from __future__ import annotations

import ast
import re
from collections.abc import Collection
from dataclasses import dataclass

from grader import parsing
from grader.submission.notebook.building import (
    DROPPED_DECORATOR,
    globals_needed,
    listed_skipped,
    unbound_globals,
    walk_cells,
)
from grader.submission.notebook.cells import SCRIPT_CELL
from grader.submission.notebook.ipython import ESCAPES, transform_cell
from grader.submission.notebook.models import NotebookModule, NotebookSummary, SkippedCode
from grader.submission.notebook.reading import Cell, NotebookCells
from grader.submission.validation import FileVerdict, check_source

IPYTHON = "get_ipython"
"""The call every export writes IPython's lines with."""
_MARKER = re.compile(r"^# ?(?:In\s*\[[ \d]*\]:|%%(?!\w))")
"""A cell marker: nbconvert's ``# In[12]:`` / ``# In[ ]:``, jupytext's and VS Code's ``# %%`` (not
``# %%time``)."""
_HELP = {"pinfo": "?", "pinfo2": "??"}
MAX_PADDING = 4_000_000
"""Blank lines written before the marked cells of a file to run (so each keeps its lines) at most; past it
the file runs as one cell (a hostile file of thousands of markers must not cost gigabytes)."""
MAX_NAMED = 5
"""Globals named in the note saying why a whole file ran at import."""
_DEFINITIONS = (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)
_IPYTHON_KINDS = frozenset({*ESCAPES.values(), "IPython magic (automagic)", "IPython command"})


def build_script(
    data: bytes, name: str, graded: Collection[str], served: Collection[str] = ()
) -> NotebookModule | FileVerdict | None:
    """The module the sandbox imports for a `.py`, read as the notebook it may have been; None when the file
    is graded as it is (nothing the notebook's rules leave out, but decorators).

    What a notebook's rules leave out is not run at import, unless a graded function uses what it sets or
    changes (``q = train()`` read by ``taxi()``, ``env.reset()`` on the ``env`` a function plays): then
    the whole file runs at import, as a `.py` always did, its IPython lines made ``pass``. The globals of
    ``served`` functions come from running the file's cells before they are called (``compare()``), so
    they ask nothing of the import.

    Args:
        data: The file's bytes (UTF-8 Python: `check_source` passed).
        name: Its name, in messages.
        graded: The functions problems call.
        served: Those of them whose globals the file's cells set before the call.

    Returns:
        The module (every line and cell cited as the file's own line: cell `SCRIPT_CELL`), None to grade the
        file as it is (also when it defines nothing: what it does at import is then its verdict), or a
        verdict when the module built is not Python.
    """
    text = data.decode("utf-8-sig")
    cells = script_cells(text)
    by_number = dict(enumerate(cells, 1))
    builder = walk_cells(as_notebook_cells(cells), name, graded, script=True)

    def in_file(entry: SkippedCode) -> SkippedCode:
        line = by_number[entry.cell].file_line(entry.line) if entry.cell in by_number else entry.line
        return entry.model_copy(update={"cell": SCRIPT_CELL, "line": line})

    listed = [in_file(entry) for entry in builder.skipped + builder.unlisted]
    ipython = [
        entry for entry in listed if entry.reason in _IPYTHON_KINDS or entry.reason.startswith("cell magic")
    ]
    if not ipython and not builder.broken and all(entry.reason == DROPPED_DECORATOR for entry in listed):
        return None
    runnable = [(by_number[number], source) for number, source in builder.runnable]
    # The whole file as it runs: each cell on its lines, but a cell that is not Python (Run All fails there).
    whole_source, whole = _placed([(cell.lines, source) for cell, source in runnable if _parsed(source)])
    run_cells = _runnable_cells(runnable, whole_source, marked=_has_markers(text))
    source, origins = _aligned(builder.future, builder.kept, builder.origins, by_number)
    if not any(isinstance(kept, _DEFINITIONS) for kept in parsing.parse(source).body) and not builder.broken:
        return None  # nothing to call: what the file does at import is its verdict, as it always was
    needed = globals_needed(source, [function for function in graded if function not in served])
    used = sorted(needed & (builder.affected | (builder.touched - builder.defined)))
    if used:
        if not ipython and not builder.broken:
            return None
        listed_names = ", ".join(f"`{name}`" for name in used[:MAX_NAMED])
        whole_file = f"your functions use what top-level statements set or change ({listed_names}), so the whole file ran at import, as a .py always did, but for its IPython lines"  # noqa: E501
        ran = builder.kept_statements + len(listed) - len(ipython)
        summary = NotebookSummary(
            code_cells=len(cells), kept_statements=ran, skipped=ipython, ignored=[whole_file], script=True
        )
        verdict = check_source(whole_source.encode(), name)
        if verdict is not None:
            return verdict
        return NotebookModule(source=whole_source, summary=summary, origins=whole, cells=run_cells)
    verdict = check_source(source.encode(), name)
    if verdict is not None:
        return verdict
    skipped_only = {
        bound: in_file(where)
        for bound, where in builder.skipped_bindings.items()
        if bound not in builder.scope.kinds
    }
    summary = NotebookSummary(
        code_cells=len(cells),
        kept_statements=builder.kept_statements,
        skipped=[in_file(entry) for entry in listed_skipped(builder)],
        unbound_globals=unbound_globals(source, skipped_only, graded),
        script=True,
    )
    return NotebookModule(source=source, summary=summary, origins=origins, cells=run_cells)


def _aligned(
    future: list[str], kept: list[str], origins: list[tuple[int, int] | None], cells: dict[int, ScriptCell]
) -> tuple[str, tuple[tuple[int, int] | None, ...]]:
    """The kept statements, each on its own line of the file where the lines before it leave room (so a
    traceback's line is the file's), with each line's (`SCRIPT_CELL`, line in the file)."""
    lines = [
        (cells[origin[0]].file_line(origin[1]) if origin[0] in cells else origin[1], text)
        for text, origin in zip("\n".join(kept).split("\n"), origins, strict=True)
        if origin is not None  # not the notebook's "# --- cell N ---" headers
    ]
    source, placed = _placed([((line,), text) for line, text in lines], first=future)
    return source, placed


def _placed(
    chunks: list[tuple[tuple[int, ...], str]],
    first: list[str] = (),  # type: ignore[assignment]
) -> tuple[str, tuple[tuple[int, int] | None, ...]]:
    """Each chunk's lines at the file's lines they came from (``chunk[0]``: the file's line of each, or of its
    first), where the lines before leave room; after ``first`` lines. The source and each line's origin."""
    lines: list[str] = list(first)
    placed: list[tuple[int, int] | None] = [None] * len(first)
    for numbers, text in chunks:
        for index, line_text in enumerate(text.split("\n")):
            line = numbers[min(index, len(numbers) - 1)] + max(0, index - len(numbers) + 1)
            while len(lines) < line - 1:
                lines.append("")
                placed.append(None)
            lines.append(line_text)
            placed.append((SCRIPT_CELL, line))
    return "\n".join(lines) + "\n", tuple(placed)


def _runnable_cells(
    runnable: list[tuple[ScriptCell, str]], whole: str, *, marked: bool
) -> tuple[tuple[int, str], ...]:
    """What running the file's cells runs, as Run All runs its notebook's (IPython's lines ``pass``, a
    ``%%time`` cell's body, no ``%%bash`` cell): its marked cells, each after blank lines so that its lines
    are the file's, or the file as one cell (``whole``); each a script's (`SCRIPT_CELL`)."""
    if not marked or sum(cell.first_line for cell, _ in runnable) > MAX_PADDING:
        return ((SCRIPT_CELL, whole),)
    return tuple((SCRIPT_CELL, _placed([(cell.lines, source)])[0]) for cell, source in runnable)


def _has_markers(text: str) -> bool:
    return any(_MARKER.match(line) for line in text.splitlines())


@dataclass(frozen=True)
class ScriptCell:
    """One cell of a `.py`: its source, IPython's lines as the notebook had them, and the file's line of each
    of its lines (a cell magic's body is written out below its header, all on the line of its call)."""

    source: str
    lines: tuple[int, ...]

    @property
    def first_line(self) -> int:
        """The cell's first line in the file."""
        return self.lines[0]

    def file_line(self, line: int) -> int:
        """The file's line of the cell's line ``line`` (1-based)."""
        return self.lines[min(max(line, 1), len(self.lines)) - 1]


def defines_only(tree: ast.Module, text: str) -> bool:
    """True when importing the file runs nothing but imports, definitions and its docstring (an
    ``if __name__ == "__main__":`` block is not run by an import either) and no IPython line is in it."""
    if IPYTHON in text:
        return False
    for statement in tree.body:
        match statement:
            case (
                ast.Import() | ast.ImportFrom() | ast.FunctionDef() | ast.AsyncFunctionDef() | ast.ClassDef()
            ):
                continue
            case ast.Expr(value=ast.Constant(value=str())):
                continue
            case ast.If() if is_main_guard(statement.test):
                continue
        return False
    return True


_IPYTHON_LINE = re.compile(r"^\s*[!%]|\?\s*$", re.M)


def may_be_export(text: str) -> bool:
    """Whether a file that is not Python may be a notebook's export all the same: a line IPython reads
    (``!pip install gym``, ``%matplotlib inline``, ``gym.make?``) or a cell marker."""
    return _IPYTHON_LINE.search(text) is not None or any(_MARKER.match(line) for line in text.splitlines())


def is_main_guard(test: ast.expr) -> bool:
    """``__name__ == "__main__"`` (either way round)."""
    return (
        isinstance(test, ast.Compare)
        and any(isinstance(node, ast.Name) and node.id == "__name__" for node in ast.walk(test))
        and any(isinstance(node, ast.Constant) and node.value == "__main__" for node in ast.walk(test))
    )


def script_cells(text: str) -> list[ScriptCell]:
    """The file's cells: by its markers, or one per top-level statement; IPython's lines as the notebook had
    them.

    A file that is not Python as it is may still be an export: its IPython lines written as they are
    (``!pip install gym``, which IPython's transformer reads), or a marked cell that is not Python (a
    half-written cell, left out as the notebook reader leaves it out).

    Raises:
        SyntaxError: The file is not Python, even read as IPython reads a cell, and has no cell markers.
    """
    lines = text.splitlines()
    tree = _parsed(text) or _parsed(transform_cell(text, ()).source)
    if tree is None:
        markers = [number for number, line in enumerate(lines, 1) if _MARKER.match(line)]
        if not markers:
            raise SyntaxError("not Python, even as IPython reads a cell, and no cell markers")
        return _cells(lines, sorted({1, *markers}), None)
    return _cells(lines, _cell_starts(tree, lines), tree)


def _parsed(text: str) -> ast.Module | None:
    try:
        return parsing.parse(text)
    except (SyntaxError, ValueError):
        return None


def _cells(lines: list[str], starts: list[int], tree: ast.Module | None) -> list[ScriptCell]:
    cells: list[ScriptCell] = []
    for index, start in enumerate(starts):
        end = starts[index + 1] - 1 if index + 1 < len(starts) else len(lines)
        chunk = lines[start - 1 : end]
        if chunk and _MARKER.match(chunk[0]):
            chunk[0] = ""  # the marker separates cells; it is no line of the cell
        if not any(line.strip() for line in chunk):
            continue
        if tree is not None:
            statements = [s for s in tree.body if start <= _first_line(s) <= end]
        else:  # each marked cell alone; one that is not Python is left out by the notebook's rules
            alone = _parsed("\n".join(chunk))
            if alone is not None:
                ast.increment_lineno(alone, start - 1)
            statements = alone.body if alone is not None else []
        written, numbers = unexported(chunk, statements, start)
        cells.append(ScriptCell("\n".join(written), tuple(numbers)))
    return cells


def as_notebook_cells(cells: list[ScriptCell]) -> NotebookCells:
    """The cells as the notebook reader takes them (numbered 1, 2, ... in the file's order)."""
    return NotebookCells([Cell(number, None, cell.source) for number, cell in enumerate(cells, 1)], [])


def _cell_starts(tree: ast.Module, lines: list[str]) -> list[int]:
    """First line of each cell: after each marker outside a statement, else at each top-level statement."""
    inside: set[int] = set()
    for statement in tree.body:
        inside.update(range(_first_line(statement) + 1, (statement.end_lineno or statement.lineno) + 1))
    markers = [number for number, line in enumerate(lines, 1) if _MARKER.match(line) and number not in inside]
    if markers:
        return sorted({1, *markers})
    starts = [_first_line(statement) for statement in tree.body]
    return sorted({1, *starts[1:]}) if starts else [1]


def _first_line(statement: ast.stmt) -> int:
    decorators: list[ast.expr] = getattr(statement, "decorator_list", [])
    return min([statement.lineno, *(decorator.lineno for decorator in decorators)])


def unexported(chunk: list[str], statements: list[ast.stmt], first_line: int) -> tuple[list[str], list[int]]:
    """The chunk's lines with each ``get_ipython()`` line written back as the IPython line it came from, and
    the file's line of each."""
    lines = list(chunk)
    numbers = list(range(first_line, first_line + len(chunk)))
    top_level = {id(statement) for statement in statements}
    found = [
        (node, call)
        for statement in statements
        for node in ast.walk(statement)
        if (call := _ipython_call(node))
    ]
    # From the last line up, so a cell magic's body written out below its header moves no line still to do.
    for node, (method, args) in sorted(found, key=lambda item: -item[0].lineno):  # type: ignore[attr-defined]
        row = node.lineno - first_line  # type: ignore[attr-defined]
        if not 0 <= row < len(lines):
            continue
        indent = lines[row][: len(lines[row]) - len(lines[row].lstrip())]
        target = _assigned(node, lines[row])
        if method == "run_cell_magic":
            if id(node) not in top_level or target or len(args) != 3:
                continue
            header = f"%%{args[0]} {args[1]}".rstrip()
            body = args[2].removesuffix("\n").split("\n")
            replaced = [header, *body]
        else:
            replaced = [indent + target + _line_of(method, args, bool(target))]
        end = (node.end_lineno or node.lineno) - first_line  # type: ignore[attr-defined]
        # The escape's line replaces the call's; its other lines (if any) are left empty, and a
        # cell magic's body follows its header (the cell was that call alone).
        padded = replaced + [""] * max(0, end - row + 1 - len(replaced))
        lines[row : end + 1] = padded
        numbers[row : end + 1] = [numbers[row] + min(index, end - row) for index in range(len(padded))]
    return lines, numbers


def _ipython_call(node: ast.AST) -> tuple[str, list[str]] | None:
    """(method, its string arguments) for ``get_ipython().method('...', ...)`` as a statement or the value of
    an assignment to names, else None."""
    assigned = isinstance(node, ast.Assign) and all(_names(target) for target in node.targets)
    if not isinstance(node, ast.Expr) and not assigned:
        return None
    value = node.value  # type: ignore[attr-defined]
    match value:
        case ast.Call(
            func=ast.Attribute(
                value=ast.Call(func=ast.Name(id="get_ipython"), args=[], keywords=[]), attr=method
            ),
            args=args,
            keywords=[],
        ) if all(isinstance(arg, ast.Constant) and isinstance(arg.value, str) for arg in args):
            if method in ("run_line_magic", "run_cell_magic", "system", "getoutput"):
                return method, [arg.value for arg in args]  # type: ignore[attr-defined]
    return None


def _names(target: ast.expr) -> bool:
    if isinstance(target, ast.Tuple | ast.List):
        return all(_names(element) for element in target.elts)
    return isinstance(target, ast.Name)


def _assigned(node: ast.AST, line: str) -> str:
    """``x = `` of ``x = get_ipython().getoutput('ls')`` (its text up to the call), "" for a statement."""
    if not isinstance(node, ast.Assign) or node.value.lineno != node.lineno:
        return ""
    return line[node.col_offset : node.value.col_offset]


def _line_of(method: str, args: list[str], assigned: bool) -> str:
    if method == "run_line_magic" and len(args) == 2:
        name, rest = args
        if name in _HELP:
            return rest + _HELP[name]
        return f"%{name} {rest}".rstrip()
    if method == "system" and len(args) == 1:
        return "!" + args[0]
    if method == "getoutput" and len(args) == 1:
        return ("!" if assigned else "!!") + args[0]
    return f"%{method}"  # an unknown shape: still an IPython line, left out as the notebook's would be
