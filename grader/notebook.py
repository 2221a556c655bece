"""Build the graded module of a Jupyter notebook: its imports and definitions, never its demo statements.

A notebook's code cells mix what the grader needs (imports, ``def``/``class``, constants such as
``ALPHA = .1`` or ``env = gym.make("Taxi-v3")``) with what a student runs to look at results (``print``,
plots, ``for n in range(1, 22): ...``, ``%timeit``, ``!pip install gym``, ``q = find_qvalues("Taxi-v3")``).
Only the first kind runs at import; every statement left out is listed, cell by cell, in the report.

A definition that reads a global which only a left-out statement sets (``def taxi(): ... q[state]`` after
``q = find_qvalues(...)``) is still graded, as the student wrote it, and the problem's feedback says which
global is missing and where it came from: the verdict is never silently wrong, and running a training loop
at import (minutes, and a different table than the one the function would compute) is never needed.
"""

from __future__ import annotations

import ast
import builtins
import json
import re
import symtable
import warnings
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field

from pydantic import BaseModel, ConfigDict, Field

from grader.validation import FileVerdict, check_source

NOTEBOOK_SUFFIX = ".ipynb"
MAX_NOTEBOOK_BYTES = 20_000_000
"""Outputs (plots, rendered frames) make notebooks large; only the code cells are graded, and they are
held to the ``.py`` limit once extracted."""
MAX_CODE_CHARS = 120
"""A skipped statement is shown by its first line, cut to this length."""

CHEAP_CALLS: frozenset[str] = frozenset(
    {
        "gym.make",
        "gymnasium.make",
        *(
            f"numpy.{name}"
            for name in ("array", "zeros", "ones", "full", "empty", "arange", "linspace", "eye", "asarray")
        ),
        *("range", "list", "tuple", "dict", "set", "frozenset", "int", "float", "str", "bool", "len"),
    }
)
"""Calls an assignment may make and still run at import: constructors that cost nothing and are how real
notebooks set up shared state (``env = gym.make("CartPole-v0")``, ``q = np.zeros((500, 6))``)."""

PYTHON_CELL_MAGICS = frozenset({"%%time", "%%capture"})
"""Cell magics whose cell is Python run in the notebook's namespace, so its definitions count; the body
of any other cell magic (``%%bash``, ``%%writefile``, ``%%timeit``, ...) is not the module's code."""
_MAGIC_LINE = re.compile(r"^\s*(?:[%!?]|[A-Za-z_][\w.]*\s*=\s*[%!])|^\s*[\w.]+\?{1,2}\s*$")
_MAIN_GUARD = "__main__"


class SkippedCode(BaseModel):
    """One statement of a notebook cell the grader did not run."""

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

    def note(self) -> str:
        """The sentence added to the feedback of the problem named after ``function``."""
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
    """

    source: str
    summary: NotebookSummary
    origins: tuple[tuple[int, int] | None, ...] = ()

    def cited(self, text: str, module_name: str) -> str:
        """``text`` with ``File ".../<module_name>", line N`` rewritten to the notebook's cell and line."""

        def replace(match: re.Match[str]) -> str:
            number = int(match.group("line"))
            origin = self.origins[number - 1] if 0 < number <= len(self.origins) else None
            if origin is None:
                return match.group(0)
            return f'File "{match.group("name").removesuffix(".py")}", cell {origin[0]}, line {origin[1]}'

        pattern = rf'File "(?:[^"]*/)?(?P<name>{re.escape(module_name)})", line (?P<line>\d+)'
        return re.sub(pattern, replace, text)


@dataclass
class _Cell:
    number: int
    execution_count: int | None
    source: str


@dataclass
class _Builder:
    """Walks the code cells in order, keeping what may run at import and recording the rest."""

    kept: list[str] = field(default_factory=list)
    origins: list[tuple[int, int] | None] = field(default_factory=list)
    future: list[str] = field(default_factory=list)
    skipped: list[SkippedCode] = field(default_factory=list)
    skipped_bindings: dict[str, SkippedCode] = field(default_factory=dict)
    bound: set[str] = field(default_factory=lambda: set(dir(builtins)))
    aliases: dict[str, str] = field(default_factory=dict)
    kept_statements: int = 0


def is_notebook(name: str) -> bool:
    """True when a submission's file name says it is a Jupyter notebook."""
    return name.lower().endswith(NOTEBOOK_SUFFIX)


def build_module(data: bytes, name: str) -> NotebookModule | FileVerdict:
    """Turn a notebook's bytes into the Python module the grader imports, without running any of it.

    Args:
        data: The ``.ipynb`` file's bytes.
        name: Its file name, used in messages.

    Returns:
        The module source and the summary of what was left out, or the verdict saying why the notebook
        cannot be graded (not JSON, not nbformat 4, not Python, no code, a cell that is not valid Python).
    """
    cells = _read_cells(data, name)
    if isinstance(cells, FileVerdict):
        return cells
    builder = _Builder()
    for cell in cells:
        problem = _add_cell(builder, cell, name)
        if problem is not None:
            return problem
    if builder.kept_statements == 0:
        return FileVerdict(
            "missing",
            f"{name} has code cells, but none of them defines anything: "
            "only imports and top-level demo statements. "
            "Put your functions (random_blackjack, blackjack, cartpole, car, taxi) in `def` statements and submit again.",  # noqa: E501
        )
    source = "\n".join([*builder.future, *builder.kept]) + "\n"
    verdict = check_source(source.encode(), name)
    if verdict is not None:
        return verdict
    summary = NotebookSummary(
        code_cells=len(cells),
        kept_statements=builder.kept_statements,
        skipped=builder.skipped,
        unbound_globals=_unbound_globals(
            source,
            {name: where for name, where in builder.skipped_bindings.items() if name not in builder.bound},
        ),
    )
    origins = [None] * len(builder.future) + builder.origins
    return NotebookModule(source=source, summary=summary, origins=tuple(origins))


def _read_cells(data: bytes, name: str) -> list[_Cell] | FileVerdict:
    import nbformat

    if len(data) > MAX_NOTEBOOK_BYTES:
        return FileVerdict(
            "error",
            f"{name} is {len(data):,} bytes; a notebook may be at most {MAX_NOTEBOOK_BYTES:,} bytes. "
            "Clear its outputs (Kernel > Restart & Clear Output) and submit again.",
        )
    if not data.strip():
        return FileVerdict("missing", f"{name} is empty: nothing to grade. Submit your saved notebook.")
    try:
        text = data.decode("utf-8")
        with warnings.catch_warnings():  # nbformat warns about what Jupyter repairs silently (cell ids)
            warnings.simplefilter("ignore")
            notebook = nbformat.reads(text, as_version=nbformat.NO_CONVERT)  # type: ignore[no-untyped-call]
    except (UnicodeDecodeError, json.JSONDecodeError, nbformat.reader.NotJSONError) as error:
        detail = str(error).splitlines()[0][:200] if str(error) else type(error).__name__
        return FileVerdict(
            "error",
            f"{name} is not a readable notebook: it is not valid JSON ({detail}). "
            "Open it in Jupyter, save it again (File > Save) and submit the saved .ipynb, or submit your code as a .py file.",  # noqa: E501
        )
    except nbformat.ValidationError as error:
        return _invalid(name, error)
    except (ValueError, TypeError, KeyError, AttributeError):
        return FileVerdict(
            "error",
            f'{name} is JSON but not a Jupyter notebook (expected an object with "nbformat" and "cells"). '
            "Submit the .ipynb file Jupyter saved, or your code as a .py file.",
        )
    version = notebook.get("nbformat")
    if version != 4:
        return FileVerdict(
            "error",
            f"{name} is a notebook in format version {version}; "
            "the grader reads nbformat 4 (Jupyter since 2015). "
            "Open it in a current Jupyter, save it, and submit again.",
        )
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            nbformat.validate(notebook)
    except nbformat.ValidationError as error:
        return _invalid(name, error)
    language = str(notebook.get("metadata", {}).get("language_info", {}).get("name", "python"))
    if language.lower() != "python":
        return FileVerdict(
            "error",
            f"{name} is a {language} notebook; the lab is graded in Python. Submit a Python notebook.",
        )
    cells = [
        _Cell(number, cell.get("execution_count"), str(cell.get("source", "")))
        for number, cell in enumerate(notebook.get("cells", []), start=1)
        if cell.get("cell_type") == "code" and str(cell.get("source", "")).strip()
    ]
    if not cells:
        return FileVerdict(
            "missing",
            f"{name} has no code cells: nothing to grade. Submit the notebook with your functions in it.",
        )
    return cells


def _invalid(name: str, error: Exception) -> FileVerdict:
    detail = str(getattr(error, "message", error)).splitlines()[0][:200]
    return FileVerdict(
        "error",
        f"{name} is not a valid nbformat 4 notebook: {detail}. "
        "Open it in Jupyter, save it again and submit the saved file.",
    )


def _add_cell(builder: _Builder, cell: _Cell, name: str) -> FileVerdict | None:
    first = cell.source.lstrip().splitlines()[0]
    magic = first.split()[0] if first.startswith("%%") else None
    if magic is not None and magic not in PYTHON_CELL_MAGICS:
        _skip_cell(builder, cell, f"cell magic {magic}: the whole cell is left out")
        return None
    if magic is not None:  # the magic line goes; the cell's Python is judged statement by statement
        _skip_cell(builder, cell, f"cell magic {magic} (the cell's statements are judged like any other's)")
        lines = cell.source.splitlines()
        index = next(number for number, line in enumerate(lines) if line.strip())
        lines[index] = ""
        cell = _Cell(cell.number, cell.execution_count, "\n".join(lines))
    source = cell.source
    try:
        tree = ast.parse(source)
    except SyntaxError:
        source = _without_ipython_lines(builder, cell)
        try:
            tree = ast.parse(source)
        except SyntaxError as error:
            return FileVerdict(
                "error",
                f"{name}: code cell {cell.number}"
                + (f" (In [{cell.execution_count}])" if cell.execution_count is not None else "")
                + f" is not valid Python: {error.msg} (line {error.lineno} of the cell). "
                "Fix the cell, save the notebook and submit again.",
            )
        except (ValueError, RecursionError, MemoryError) as error:
            return FileVerdict("error", f"{name}: code cell {cell.number} cannot be parsed ({error}).")
    lines = source.splitlines()
    kept_any = False
    for statement in tree.body:
        if isinstance(statement, ast.Pass):  # also what magics and shell lines were replaced by
            continue
        reason = _skip_reason(builder, statement)
        text = _statement_text(lines, statement)
        if reason is None:
            if _is_future_import(statement):
                builder.future.append(text)
            else:
                if not kept_any:
                    builder.kept.append(f"# --- notebook cell {cell.number} ---")
                    builder.origins.append(None)
                    kept_any = True
                builder.kept.append(text)
                start = _first_line(statement)
                builder.origins += [(cell.number, start + offset) for offset in range(text.count("\n") + 1)]
            builder.kept_statements += 1
            _bind(builder, statement)
        else:
            skipped = SkippedCode(
                cell=cell.number,
                execution_count=cell.execution_count,
                line=_first_line(statement),
                reason=reason,
                code=_shortened(text),
            )
            builder.skipped.append(skipped)
            for bound_name in _bound_names(statement):
                if bound_name not in builder.bound:
                    builder.skipped_bindings.setdefault(bound_name, skipped)
    return None


def _skip_cell(builder: _Builder, cell: _Cell, reason: str) -> None:
    builder.skipped.append(
        SkippedCode(
            cell=cell.number,
            execution_count=cell.execution_count,
            line=1,
            reason=reason,
            code=_shortened(cell.source.strip().splitlines()[0]),
        )
    )


def _without_ipython_lines(builder: _Builder, cell: _Cell) -> str:
    """The cell with magics, shell commands and help requests replaced by ``pass`` (same indentation)."""
    lines = cell.source.splitlines()
    for index, line in enumerate(lines):
        if _MAGIC_LINE.match(line):
            stripped = line.strip()
            kind = (
                "shell command"
                if "!" in stripped[:1] or re.match(r"[\w.]+\s*=\s*!", stripped)
                else "help request"
                if stripped.startswith("?") or stripped.endswith("?")
                else "IPython magic"
            )
            builder.skipped.append(
                SkippedCode(
                    cell=cell.number,
                    execution_count=cell.execution_count,
                    line=index + 1,
                    reason=kind,
                    code=_shortened(stripped),
                )
            )
            lines[index] = line[: len(line) - len(line.lstrip())] + "pass"
    return "\n".join(lines)


def _skip_reason(builder: _Builder, statement: ast.stmt) -> str | None:
    """None when the statement runs at import; otherwise what it is, in the student's words."""
    match statement:
        case ast.Import() | ast.ImportFrom():
            return None
        case ast.FunctionDef() | ast.AsyncFunctionDef() | ast.ClassDef():
            evaluated = [*statement.decorator_list]
            if isinstance(statement, ast.FunctionDef | ast.AsyncFunctionDef):
                evaluated += [*statement.args.defaults, *(d for d in statement.args.kw_defaults if d)]
            else:
                evaluated += [*statement.bases, *(keyword.value for keyword in statement.keywords)]
            unsafe = [node for node in evaluated if not _is_simple(builder, node)]
            return "definition whose defaults or decorators run a computation" if unsafe else None
        case ast.Expr(value=ast.Constant()):
            return None
        case ast.Expr(value=ast.Call() as call):
            return f"call of {_dotted(call.func) or 'an expression'}(...) (a demo, not run at import)"
        case ast.Expr():
            return "expression whose value Jupyter displays"
        case ast.Assign() | ast.AnnAssign() | ast.AugAssign():
            return _assignment_reason(builder, statement)
        case ast.If() if _is_main_guard(statement.test):
            return "`if __name__ == '__main__':` block (a demo)"
        case ast.If() | ast.Try() if _only_definitions(builder, statement):
            return None
        case ast.For() | ast.AsyncFor() | ast.While():
            return "loop (a demo or training run, not run at import)"
        case ast.With() | ast.AsyncWith():
            return "`with` block (a demo, not run at import)"
        case ast.Try():
            return "`try` block running code (a demo, not run at import)"
        case ast.If():
            return "`if` block running code (a demo, not run at import)"
    return f"top-level `{type(statement).__name__.lower()}` statement (not run at import)"


def _assignment_reason(
    builder: _Builder, statement: ast.Assign | ast.AnnAssign | ast.AugAssign
) -> str | None:
    targets = statement.targets if isinstance(statement, ast.Assign) else [statement.target]
    if not all(_is_name_target(target) for target in targets):
        return "assignment into an object (not run at import)"
    if statement.value is None or _is_simple(builder, statement.value):
        if isinstance(statement, ast.AugAssign) and not all(
            isinstance(target, ast.Name) and target.id in builder.bound for target in targets
        ):
            return "update of a name no kept statement sets"
        return None
    missing = sorted(
        node.id
        for node in ast.walk(statement.value)
        if isinstance(node, ast.Name) and node.id in builder.skipped_bindings and node.id not in builder.bound
    )
    if missing:
        return f"assignment using {', '.join(f'`{name}`' for name in missing)}, set by a skipped statement"
    return "assignment computed by a call (a demo or training run, not run at import)"


def _is_name_target(target: ast.expr) -> bool:
    if isinstance(target, ast.Tuple | ast.List):
        return all(_is_name_target(element) for element in target.elts)
    return isinstance(target, ast.Name)


def _only_definitions(builder: _Builder, statement: ast.If | ast.Try) -> bool:
    if isinstance(statement, ast.If) and not _is_simple(builder, statement.test):
        return False
    blocks: list[list[ast.stmt]]
    if isinstance(statement, ast.If):
        blocks = [statement.body, statement.orelse]
    else:
        blocks = [statement.body, statement.orelse, statement.finalbody]
        blocks += [handler.body for handler in statement.handlers]
    return all(_skip_reason(builder, inner) is None for block in blocks for inner in block)


def _is_main_guard(test: ast.expr) -> bool:
    return (
        isinstance(test, ast.Compare)
        and any(isinstance(node, ast.Name) and node.id == "__name__" for node in ast.walk(test))
        and any(isinstance(node, ast.Constant) and node.value == _MAIN_GUARD for node in ast.walk(test))
    )


def _is_simple(builder: _Builder, node: ast.expr, local: frozenset[str] = frozenset()) -> bool:
    """True when evaluating ``node`` at import costs nothing and reads only what already ran."""
    match node:
        case ast.Constant():
            return True
        case ast.Name():
            return node.id in builder.bound or node.id in local
        case ast.Attribute():
            return _is_simple(builder, node.value, local)
        case ast.Lambda():
            return all(
                _is_simple(builder, d, local) for d in [*node.args.defaults, *node.args.kw_defaults] if d
            )
        case ast.Call():
            canonical = _canonical_call(builder, node.func)
            arguments = [*node.args, *(keyword.value for keyword in node.keywords)]
            return canonical in CHEAP_CALLS and all(_is_simple(builder, arg, local) for arg in arguments)
        case ast.ListComp() | ast.SetComp() | ast.GeneratorExp() | ast.DictComp():
            names = set(local)
            for generator in node.generators:
                if not _is_simple(builder, generator.iter, frozenset(names)):
                    return False
                names |= {n.id for n in ast.walk(generator.target) if isinstance(n, ast.Name)}
                if not all(_is_simple(builder, cond, frozenset(names)) for cond in generator.ifs):
                    return False
            parts = [node.key, node.value] if isinstance(node, ast.DictComp) else [node.elt]
            return all(_is_simple(builder, part, frozenset(names)) for part in parts)
        case ast.Starred():
            return _is_simple(builder, node.value, local)
    simple_kinds = (
        ast.BinOp, ast.UnaryOp, ast.BoolOp, ast.Compare, ast.IfExp, ast.Tuple, ast.List, ast.Set, ast.Dict,
        ast.Subscript, ast.Slice, ast.JoinedStr, ast.FormattedValue, ast.operator, ast.unaryop, ast.boolop,
        ast.cmpop, ast.expr_context,
    )  # fmt: skip
    if not isinstance(node, simple_kinds):
        return False
    return all(
        _is_simple(builder, child, local) if isinstance(child, ast.expr) else isinstance(child, simple_kinds)
        for child in ast.iter_child_nodes(node)
    )


def _canonical_call(builder: _Builder, function: ast.expr) -> str:
    dotted = _dotted(function)
    if dotted is None:
        return ""
    head, _, rest = dotted.partition(".")
    base = builder.aliases.get(head, head)
    return f"{base}.{rest}" if rest else base


def _dotted(node: ast.expr) -> str | None:
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        inner = _dotted(node.value)
        return f"{inner}.{node.attr}" if inner else None
    return None


def _bind(builder: _Builder, statement: ast.stmt) -> None:
    for node in _statements(statement):
        if isinstance(node, ast.Import):
            for alias in node.names:
                builder.aliases[alias.asname or alias.name.split(".")[0]] = (
                    alias.name if alias.asname else alias.name.split(".")[0]
                )
        elif isinstance(node, ast.ImportFrom) and node.module:
            for alias in node.names:
                builder.aliases[alias.asname or alias.name] = f"{node.module}.{alias.name}"
    builder.bound |= _bound_names(statement)


def _statements(statement: ast.stmt) -> Iterator[ast.stmt]:
    """The statement and those nested in its blocks, not entering definitions."""
    yield statement
    if isinstance(statement, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef | ast.Lambda):
        return
    for child in ast.iter_child_nodes(statement):
        if isinstance(child, ast.stmt):
            yield from _statements(child)
        elif isinstance(child, ast.ExceptHandler):
            for inner in child.body:
                yield from _statements(inner)


def _bound_names(statement: ast.stmt) -> set[str]:
    """Names a top-level statement sets in the module's namespace."""
    names: set[str] = set()
    for node in _statements(statement):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            names.add(node.name)
        elif isinstance(node, ast.Import | ast.ImportFrom):
            names |= {alias.asname or alias.name.split(".")[0] for alias in node.names if alias.name != "*"}
        elif isinstance(node, ast.ExceptHandler) and node.name:
            names.add(node.name)
        else:
            targets = [
                child
                for child in ast.iter_child_nodes(node)
                if isinstance(child, ast.expr) and not isinstance(child, ast.Lambda)
            ]
            for target in targets:
                names |= {
                    inner.id
                    for inner in ast.walk(target)
                    if isinstance(inner, ast.Name) and isinstance(inner.ctx, ast.Store)
                }
    return names


def _unbound_globals(source: str, skipped_bindings: dict[str, SkippedCode]) -> list[UnboundGlobal]:
    """For each top-level function, the skipped-only globals its body reads, directly or via calls."""
    module = symtable.symtable(source, "notebook", "exec")
    reads: dict[str, set[str]] = {}  # top-level functions and classes (a class reads what its methods read)
    functions: list[str] = []
    for child in module.get_children():
        if child.get_type() in ("function", "class"):
            reads[child.get_name()] = set(_globals_read(child))
            if child.get_type() == "function":
                functions.append(child.get_name())
    entries: list[UnboundGlobal] = []
    for function in sorted(functions):
        reachable, frontier = {function}, [function]
        while frontier:
            for name in reads[frontier.pop()]:
                if name in reads and name not in reachable:
                    reachable.add(name)
                    frontier.append(name)
        missing = sorted({name for caller in reachable for name in reads[caller]} & set(skipped_bindings))
        for name in missing:
            where = skipped_bindings[name]
            entries.append(
                UnboundGlobal(function=function, name=name, cell=where.cell, line=where.line, code=where.code)
            )
    return entries


def _globals_read(table: symtable.SymbolTable) -> Iterator[str]:
    for symbol in table.get_symbols():
        if symbol.is_global() and symbol.is_referenced():
            yield symbol.get_name()
    for child in table.get_children():
        yield from _globals_read(child)


def _is_future_import(statement: ast.stmt) -> bool:
    return isinstance(statement, ast.ImportFrom) and statement.module == "__future__"


def _first_line(statement: ast.stmt) -> int:
    decorators: Sequence[ast.expr] = getattr(statement, "decorator_list", ())
    return min([statement.lineno, *(decorator.lineno for decorator in decorators)])


def _statement_text(lines: list[str], statement: ast.stmt) -> str:
    """The statement's own source: from its first decorator or column to its end, comments inside kept."""
    first, last = _first_line(statement), statement.end_lineno or statement.lineno
    chunk = lines[first - 1 : last]
    start_column = statement.col_offset if first == statement.lineno else 0
    end_column = statement.end_col_offset
    if end_column is not None:
        chunk[-1] = chunk[-1][:end_column]
    chunk[0] = chunk[0][start_column:]
    return "\n".join(chunk)


def _shortened(text: str) -> str:
    first = text.strip().splitlines()[0] if text.strip() else ""
    suffix = " ..." if "\n" in text.strip() else ""
    return first[:MAX_CODE_CHARS] + (" ..." if len(first) > MAX_CODE_CHARS else suffix)
