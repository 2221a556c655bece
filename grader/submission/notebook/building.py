"""Build the graded module of a notebook: its imports and definitions, never its demo statements.

A notebook's code cells mix what the grader needs (imports, ``def``/``class``, constants such as
``ALPHA = .1`` or ``env = gym.make("Taxi-v3")``) with what a student runs to look at results (``print``,
plots, ``for n in range(1, 22): ...``, ``%timeit``, ``!pip install gym``, ``q = find_qvalues("Taxi-v3")``).
Only the first kind runs at import (`grader.submission.notebook.rules` says which); every statement left out
is listed, cell by cell, in the report. Cells are first read as IPython reads them
(`grader.submission.notebook.ipython`).

A cell that is not valid Python even so (a half-written cell at the bottom) is left out with a note, as
Jupyter would have failed to run it; a function it defines becomes one that raises a ``SyntaxError``
naming the cell, so only a problem whose function (or a helper it calls) sits there errors.

A definition that reads a global which only a left-out statement sets (``def taxi(): ... q[state]`` after
``q = find_qvalues(...)``) is still graded, as the student wrote it, and the problem's feedback says which
global is missing and where it came from: the verdict is never silently wrong, and running a training loop
at import (minutes, and a different table than the one the function would compute) is never needed.

This module is pure and unbounded: `grader.submission.notebook.bounded` runs it on untrusted bytes in a child
process with time and memory limits.
"""

from __future__ import annotations

import ast
import re
import symtable
from collections.abc import Collection, Iterator, Sequence
from dataclasses import dataclass, field

from grader import parsing
from grader.submission.notebook import rules
from grader.submission.notebook.ipython import transform_cell
from grader.submission.notebook.models import NotebookModule, NotebookSummary, SkippedCode, UnboundGlobal
from grader.submission.notebook.reading import Cell, NotebookCells, read_cells
from grader.submission.notebook.rules import Kind, Scope
from grader.submission.validation import FileVerdict, check_source

MAX_CODE_CHARS = 120
"""A skipped statement is shown by its first line, cut to this length."""
PYTHON_CELL_MAGICS = frozenset({"%%time", "%%capture"})
"""Cell magics whose cell is Python run in the notebook's namespace, so its definitions count; the body
of any other cell magic (``%%bash``, ``%%writefile``, ``%%timeit``, ...) is not the module's code."""
_MAIN_GUARD = "__main__"
_DEFINED_IN_BROKEN_CELL = re.compile(r"^(?:async\s+)?(?:def|class)\s+([A-Za-z_]\w*)")
_ASSIGNED_IN_BROKEN_CELL = re.compile(r"^([A-Za-z_]\w*)\s*(?::[^=]*)?=(?!=)")
MAX_CELL_CHARS = 200_000
"""A code cell longer than this is not read (the longest honest cells are a few thousand characters):
it is left out like a cell that is not Python, so parsing stays cheap."""
MAX_DEPTH = 500
"""Deepest syntax tree a kept cell may have (honest code nests a few dozen levels; ``1+1+...+1`` nests
once per ``+``). The reduction is recursive, so a deeper cell is left out before it is walked."""
MAX_LISTED_SKIPPED = 1_000
"""Skipped statements listed one by one; the rest are counted in one last entry (a notebook of 200,000
``!echo`` lines must not make a report of 200,000 rows)."""
MAX_NOTED_GLOBALS = 20
"""Missing globals noted per graded function (the first, alphabetically): enough to say what to fix, and a
notebook of thousands of them cannot swell the report."""
COMPUTED = "assignment computed by a call (a demo or training run, not run at import)"


@dataclass
class _Builder:
    """Walks the code cells in order, keeping what may run at import and recording the rest."""

    name: str
    kept: list[str] = field(default_factory=list)
    origins: list[tuple[int, int] | None] = field(default_factory=list)
    future: list[str] = field(default_factory=list)
    skipped: list[SkippedCode] = field(default_factory=list)
    skipped_bindings: dict[str, SkippedCode] = field(default_factory=dict)
    scope: Scope = field(default_factory=Scope)
    kept_statements: int = 0
    unlisted: list[SkippedCode] = field(default_factory=list)
    broken: list[str] = field(default_factory=list)
    postponed_annotations: bool = False
    graded: Collection[str] | None = None
    runnable: list[tuple[int, str]] = field(default_factory=list)
    script: bool = False
    """Reading a `.py` (`grader.submission.notebook.script`): its ``if __name__ == "__main__":`` block is
    not listed (an import never ran it), and what the left-out statements set or change is kept in
    `affected`."""
    affected: set[str] = field(default_factory=set)
    touched: set[str] = field(default_factory=set)
    defined: set[str] = field(default_factory=set)
    """Names kept imports, definitions and classes bind (a module's attribute set, a function called, by a
    left-out statement is no global value it changed)."""

    @property
    def bound(self) -> set[str]:
        return set(self.scope.kinds)


def build_module(data: bytes, name: str, graded: Collection[str] | None = ()) -> NotebookModule | FileVerdict:
    """Turn a notebook's bytes into the Python module the grader imports, without running any of it.

    Pure and unbounded in time and memory: call `grader.submission.notebook.build_module`, which runs this in
    a bounded child process, on untrusted bytes.

    Args:
        data: The ``.ipynb`` file's bytes.
        name: Its file name, used in messages.
        graded: The functions problems call; the global-use analysis follows only what they reach
            (None: every top-level function, which costs time quadratic in their number: for tools and
            tests on known files only).

    Returns:
        The module source and the summary of what was left out, or the verdict saying why the notebook
        cannot be graded (not a notebook, not Python, no code, nothing defined).
    """
    read = read_cells(data, name)
    if isinstance(read, FileVerdict):
        return read
    return build_from_cells(read, name, graded)


def build_from_cells(
    read: NotebookCells, name: str, graded: Collection[str] | None = ()
) -> NotebookModule | FileVerdict:
    """`build_module` of a notebook whose code cells are read already
    (`grader.submission.notebook.reading`)."""
    builder = walk_cells(read, name, graded)
    if builder.kept_statements == 0:
        if builder.broken:
            return FileVerdict("error", builder.broken[0])
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
    skipped_only = {
        bound: where for bound, where in builder.skipped_bindings.items() if bound not in builder.scope.kinds
    }
    summary = NotebookSummary(
        code_cells=len(read.cells),
        kept_statements=builder.kept_statements,
        skipped=listed_skipped(builder),
        unbound_globals=unbound_globals(source, skipped_only, graded),
        ignored=read.ignored,
    )
    origins = [None] * len(builder.future) + builder.origins
    return NotebookModule(
        source=source, summary=summary, origins=tuple(origins), cells=tuple(builder.runnable)
    )


def walk_cells(
    read: NotebookCells, name: str, graded: Collection[str] | None, *, script: bool = False
) -> _Builder:
    """Every cell read in order: what is kept, what is left out and why."""
    builder = _Builder(name, graded=graded, script=script)
    for cell in read.cells:
        _add_cell(builder, cell)
    return builder


def _skip(builder: _Builder, cell: Cell, line: int, reason: str, code: str) -> SkippedCode:
    entry = SkippedCode(
        cell=cell.number,
        execution_count=cell.execution_count,
        line=line,
        reason=reason,
        code=_shortened(code),
    )
    (builder.skipped if len(builder.skipped) < MAX_LISTED_SKIPPED else builder.unlisted).append(entry)
    return entry


def listed_skipped(builder: _Builder) -> list[SkippedCode]:
    """The skipped statements as the report lists them: the first ones, then one entry counting the rest."""
    if not builder.unlisted:
        return builder.skipped
    first = builder.unlisted[0]
    rest = SkippedCode(
        cell=first.cell,
        execution_count=first.execution_count,
        line=first.line,
        reason=f"this and {len(builder.unlisted) - 1:,} more statements left out (not listed one by one)",
        code=first.code,
    )
    return [*builder.skipped, rest]


def _add_cell(builder: _Builder, cell: Cell) -> None:
    if len(cell.source) > MAX_CELL_CHARS:
        too_large = (
            f"the cell has {len(cell.source):,} characters, more than the {MAX_CELL_CHARS:,} the grader reads"
        )
        _broken_cell(builder, cell, cell.source, ValueError(too_large))
        return
    defined = builder.scope.kinds.keys() | builder.skipped_bindings.keys()
    transformed = transform_cell(cell.source, defined)
    magic = transformed.cell_magic
    if magic is not None and magic not in PYTHON_CELL_MAGICS:
        _skip(builder, cell, 1, f"cell magic {magic}: the whole cell is left out", cell.source.strip())
        return
    builder.runnable.append((cell.number, transformed.source))
    if magic is not None:
        _skip(
            builder, cell, 1, f"cell magic {magic} (the cell's statements are judged like any other's)", magic
        )
    for special in transformed.special:
        entry = _skip(builder, cell, special.line, special.kind, special.code)
        for bound in special.binds:
            builder.skipped_bindings.setdefault(bound, entry)
    try:
        tree = transformed.tree or parsing.parse(transformed.source)
    except (SyntaxError, ValueError) as error:
        _broken_cell(builder, cell, transformed.source, error)
        return
    except (MemoryError, RecursionError):  # the parser's "too complex", or building the tree from it
        _broken_cell(builder, cell, transformed.source, ValueError("its code nests too deeply to parse"))
        return
    depth = _depth(tree)
    if depth > MAX_DEPTH:
        too_deep = ValueError(
            f"its code nests {depth:,} levels deep, more than the {MAX_DEPTH} the grader reads"
        )
        _broken_cell(builder, cell, transformed.source, too_deep)
        return
    lines = transformed.source.splitlines()
    kept_any = False
    for statement in tree.body:
        if isinstance(statement, ast.Pass):  # also what magics and shell lines were replaced by
            continue
        reason, dropped = _skip_reason(builder, statement)
        text = _statement_text(lines, statement, dropped)
        if reason is None:
            if _is_future_import(statement):
                builder.future.append(text)
                builder.postponed_annotations |= any(a.name == "annotations" for a in statement.names)  # type: ignore[attr-defined]
            else:
                if not kept_any:
                    builder.kept.append(f"# --- notebook cell {cell.number} ---")
                    builder.origins.append(None)
                    kept_any = True
                builder.kept.append(text)
                builder.origins += _origins(lines, statement, dropped, cell.number)
            builder.kept_statements += 1
            if isinstance(
                statement, ast.Import | ast.ImportFrom | ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef
            ):
                builder.defined |= bound_names(statement)
            for decorator in dropped:
                _skip(builder, cell, decorator.lineno, DROPPED_DECORATOR, "@" + _segment(lines, decorator))
            _bind(builder.scope, statement, builder)
        else:
            main_guard = isinstance(statement, ast.If) and _is_main_guard(statement.test)
            if builder.script and main_guard:
                skipped = SkippedCode(
                    cell=cell.number,
                    execution_count=None,
                    line=_first_line(statement),
                    reason=reason,
                    code=_shortened(text),
                )
            else:
                skipped = _skip(builder, cell, _first_line(statement), reason, text)
                if builder.script:
                    builder.affected |= bound_names(statement)
                    builder.touched |= touched_names(statement)
            for bound_name in bound_names(statement):
                if bound_name not in builder.scope.kinds:
                    builder.skipped_bindings.setdefault(bound_name, skipped)


_BROKEN = "the whole cell is left out"
DROPPED_DECORATOR = (
    "decorator not applied: applying it would run code at import (the function is graded without it)"
)


def _broken_cell(builder: _Builder, cell: Cell, source: str, error: SyntaxError | ValueError) -> None:
    """Leave out a cell that is not Python (or too big to read); what it defines raises an error naming it
    when called."""
    if isinstance(error, SyntaxError):
        where = f"is not valid Python: {error.msg} (line {error.lineno} of the cell)"
        line = error.lineno or 1
    else:
        where, line = f"cannot be read: {error}", 1
    lines = source.splitlines()
    message = f"{builder.name}, {cell.label} {where}"
    defined = [m.group(1) for m in map(_DEFINED_IN_BROKEN_CELL.match, lines) if m is not None]
    graded = builder.graded
    missing = [
        name
        for name in dict.fromkeys(defined)
        if name not in builder.scope.kinds and (graded is None or name in graded)
    ]
    reason = (
        f"not valid Python, so Jupyter ran none of it either: {_BROKEN}"
        if isinstance(error, SyntaxError)
        else f"{error}: {_BROKEN}"
    )
    if missing:
        reason += f" (calling {', '.join(f'{name}()' for name in missing)} raises an error naming this cell)"
    offending = lines[line - 1] if 0 < line <= len(lines) else cell.source.strip()
    entry = _skip(builder, cell, line, reason, offending)
    for match in [*map(_ASSIGNED_IN_BROKEN_CELL.match, lines), *map(_DEFINED_IN_BROKEN_CELL.match, lines)]:
        if match is not None and match.group(1) not in builder.scope.kinds:
            builder.skipped_bindings.setdefault(match.group(1), entry)
    builder.broken.append(f"{message}. Fix the cell, run it, save the notebook and submit again.")
    first = True
    for name in missing:
        explained = f"{message}, so {name}() was never defined. Fix the cell, run it, save the notebook and submit again."  # noqa: E501
        text = f"\ndef {name}(*args, **kwargs):\n    raise SyntaxError({explained!r})"
        if first:
            builder.kept.append(f"# --- notebook cell {cell.number} (not valid Python) ---")
            builder.origins.append(None)
            first = False
        start = next(index for index, text_line in enumerate(lines, 1) if _defines(text_line, name))
        builder.kept.append(text)
        builder.origins += [None, (cell.number, start), (cell.number, start)]
        builder.scope.bind(name, Kind.STUDENT)


def _depth(tree: ast.AST) -> int:
    """The syntax tree's depth, walked without recursion (so an absurdly deep tree costs only its size)."""
    deepest, stack = 0, [(tree, 1)]
    while stack:
        node, depth = stack.pop()
        deepest = max(deepest, depth)
        if deepest > MAX_DEPTH:
            return deepest
        stack.extend((child, depth + 1) for child in ast.iter_child_nodes(node))
    return deepest


def _defines(line: str, name: str) -> bool:
    match = _DEFINED_IN_BROKEN_CELL.match(line)
    return match is not None and match.group(1) == name


def _skip_reason(
    builder: _Builder, statement: ast.stmt, scope: Scope | None = None
) -> tuple[str | None, list[ast.expr]]:
    """(None when the statement runs at import, else what it is in the student's words; the decorators
    left out of a kept definition)."""
    scope = scope or builder.scope
    match statement:
        case ast.Import():
            return None, []
        case ast.ImportFrom():
            return (
                (None, [])
                if statement.names[0].name != "*" or statement.level == 0
                else ("relative `import *`", [])
            )
        case ast.FunctionDef() | ast.AsyncFunctionDef():
            dropped = [d for d in statement.decorator_list if not rules.decorator_kept(d, scope)]
            evaluated = [*statement.args.defaults, *statement.args.kw_defaults]
            if not builder.postponed_annotations:
                evaluated += rules.annotations_of(statement.args, statement.returns)
            if not all(rules.stored_ok(node, scope) for node in evaluated):
                return "definition whose defaults or annotations run a computation", []
            return None, dropped
        case ast.ClassDef():
            return _class_reason(builder, statement, scope)
        case ast.Expr(value=ast.Constant()):
            return None, []
        case ast.Expr(value=ast.Call() as call):
            return (
                f"call of {rules.dotted_name(call.func) or 'an expression'}(...) (a demo, not run at import)",
                [],
            )
        case ast.Expr():
            return "expression whose value Jupyter displays", []
        case ast.Assign() | ast.AnnAssign() | ast.AugAssign():
            return _assignment_reason(builder, statement, scope), []
        case ast.If() if _is_main_guard(statement.test):
            return "`if __name__ == '__main__':` block (a demo)", []
        case ast.If() | ast.Try() if _only_definitions(builder, statement, scope):
            return None, []
        case ast.For() | ast.AsyncFor() | ast.While():
            return "loop (a demo or training run, not run at import)", []
        case ast.With() | ast.AsyncWith():
            return "`with` block (a demo, not run at import)", []
        case ast.Try():
            return "`try` block running code (a demo, not run at import)", []
        case ast.If():
            return "`if` block running code (a demo, not run at import)", []
    return f"top-level `{type(statement).__name__.lower()}` statement (not run at import)", []


def _class_reason(
    builder: _Builder, statement: ast.ClassDef, scope: Scope
) -> tuple[str | None, list[ast.expr]]:
    dropped = [d for d in statement.decorator_list if not rules.decorator_kept(d, scope)]
    for base in statement.bases:
        kind = None if isinstance(base, ast.Starred) else rules.evaluate(base, scope)
        if kind not in (Kind.SAFE, Kind.PLAIN_CLASS):
            return "class whose base is not a plain class (creating it would run code at import)", []
        if rules.hooked_base(base, scope):
            return "class whose base runs the class's own methods when it is created (an Enum)", []
    if not all(rules.safe(keyword.value, scope) for keyword in statement.keywords):
        return "class whose metaclass or class arguments run code at import", []
    body = Scope(parent=scope)
    for inner in statement.body:
        if isinstance(inner, ast.Pass):
            continue
        reason, inner_dropped = _skip_reason(builder, inner, body)
        if reason is not None or inner_dropped:
            line = inner.lineno - statement.lineno + 1
            what = reason or "a decorator"
            return f"class whose body runs code at import (line {line} of the class: {what})", []
        _bind(body, inner, builder)
    return None, dropped


def _assignment_reason(
    builder: _Builder, statement: ast.Assign | ast.AnnAssign | ast.AugAssign, scope: Scope
) -> str | None:
    targets = statement.targets if isinstance(statement, ast.Assign) else [statement.target]
    if not all(_is_name_target(target) for target in targets):
        return "assignment into an object (not run at import)"
    evaluated_annotation = isinstance(statement, ast.AnnAssign) and not builder.postponed_annotations
    if evaluated_annotation and not rules.stored_ok(statement.annotation, scope):  # type: ignore[union-attr]
        return "annotation that runs code at import"
    if isinstance(statement, ast.AugAssign):
        target = statement.target
        if not (
            isinstance(target, ast.Name)
            and scope.lookup(target.id) is not None
            and target.id in _all_kinds(scope)
        ):
            return "update of a name no kept statement sets"
        if rules.safe(target, scope) and rules.safe(statement.value, scope):
            return None
        return "update that operates on your own objects (it would run your code at import)"
    value = statement.value
    unpacking = any(isinstance(target, ast.Tuple | ast.List) for target in targets)
    if value is None:
        return None
    if unpacking and not isinstance(value, ast.Tuple | ast.List) and not rules.safe(value, scope):
        return "unpacking of a value the grader does not compute at import"
    if rules.stored_ok(value, scope):
        return None
    missing = sorted(
        {
            node.id
            for node in ast.walk(value)
            if isinstance(node, ast.Name)
            and node.id in builder.skipped_bindings
            and scope.lookup(node.id) is None
        }
    )
    if missing:
        return f"assignment using {', '.join(f'`{name}`' for name in missing)}, set by a skipped statement"
    if any(isinstance(node, ast.Call) for node in ast.walk(value)):
        return COMPUTED
    return "assignment that operates on your own functions or classes (it would run your code at import)"


def _all_kinds(scope: Scope) -> dict[str, Kind]:
    return {**(_all_kinds(scope.parent) if scope.parent else {}), **scope.kinds}


def _is_name_target(target: ast.expr) -> bool:
    if isinstance(target, ast.Tuple | ast.List):
        return all(_is_name_target(element) for element in target.elts)
    return isinstance(target, ast.Name)


def _only_definitions(builder: _Builder, statement: ast.If | ast.Try, scope: Scope) -> bool:
    if isinstance(statement, ast.If) and not rules.safe(statement.test, scope):
        return False
    blocks: list[list[ast.stmt]]
    if isinstance(statement, ast.If):
        blocks = [statement.body, statement.orelse]
    else:
        if not all(rules.safe(handler.type, scope) for handler in statement.handlers):
            return False
        blocks = [statement.body, statement.orelse, statement.finalbody]
        blocks += [handler.body for handler in statement.handlers]
    return all(_skip_reason(builder, inner, scope) == (None, []) for block in blocks for inner in block)


def _is_main_guard(test: ast.expr) -> bool:
    return (
        isinstance(test, ast.Compare)
        and any(isinstance(node, ast.Name) and node.id == "__name__" for node in ast.walk(test))
        and any(isinstance(node, ast.Constant) and node.value == _MAIN_GUARD for node in ast.walk(test))
    )


def _bind(scope: Scope, statement: ast.stmt, builder: _Builder) -> None:
    """Record the kinds of the names a kept statement binds (in a block: the join over its branches)."""
    seen: dict[str, list[Kind]] = {}
    aliases: dict[str, str] = {}
    for node in _statements(statement):
        for name, kind, alias in _bindings(node, scope, builder):
            seen.setdefault(name, []).append(kind)
            if alias is not None:
                aliases[name] = alias
    for name, kinds in seen.items():
        kind = rules.join(kinds)
        scope.bind(name, kind, aliases.get(name) if kind is Kind.SAFE and len(kinds) == 1 else None)


def _bindings(node: ast.stmt, scope: Scope, builder: _Builder) -> Iterator[tuple[str, Kind, str | None]]:
    match node:
        case ast.Import():
            for alias in node.names:
                top = alias.name.split(".")[0]
                yield (
                    (alias.asname or top),
                    rules.import_kind(alias.name, 0),
                    (alias.name if alias.asname else top),
                )
        case ast.ImportFrom():
            for alias in node.names:
                if alias.name != "*":
                    kind = rules.import_kind(node.module, node.level)
                    yield alias.asname or alias.name, kind, f"{node.module}.{alias.name}"
        case ast.FunctionDef() | ast.AsyncFunctionDef():
            decorators = [rules.dotted_name(d) for d in node.decorator_list]
            is_property = decorators == ["property"] or any(
                isinstance(d, ast.Attribute) and d.attr in ("setter", "getter", "deleter")
                for d in node.decorator_list
            )
            yield node.name, Kind.PROPERTY if is_property else Kind.STUDENT, None
        case ast.ClassDef():
            hooks = any(
                isinstance(inner, ast.FunctionDef | ast.AsyncFunctionDef) and inner.name in rules.CLASS_HOOKS
                for inner in node.body
            )
            plain = not hooks and not node.keywords and not node.decorator_list
            yield node.name, Kind.PLAIN_CLASS if plain else Kind.STUDENT, None
        case ast.Assign() | ast.AnnAssign():
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            value = rules.evaluate(node.value, scope) if node.value is not None else None
            for target in targets:
                single = isinstance(target, ast.Name)
                for inner in ast.walk(target):
                    if isinstance(inner, ast.Name):
                        kind = value if single and value is not None else Kind.STUDENT
                        if not single and value is Kind.SAFE:
                            kind = Kind.SAFE
                        yield inner.id, kind, None
        case ast.AugAssign() if isinstance(node.target, ast.Name):
            yield node.target.id, Kind.SAFE, None
        case ast.Try():
            for handler in node.handlers:
                if handler.name:
                    yield handler.name, Kind.STUDENT, None


def _statements(statement: ast.stmt) -> Iterator[ast.stmt]:
    """The statement and those nested in its blocks, not entering definitions."""
    yield statement
    if isinstance(statement, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
        return
    for child in ast.iter_child_nodes(statement):
        if isinstance(child, ast.stmt):
            yield from _statements(child)
        elif isinstance(child, ast.ExceptHandler):
            for inner in child.body:
                yield from _statements(inner)


def bound_names(statement: ast.stmt) -> set[str]:
    """Names a top-level statement sets in the module's namespace."""
    names: set[str] = set()
    for node in _statements(statement):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            names.add(node.name)
        elif isinstance(node, ast.Import | ast.ImportFrom):
            names |= {alias.asname or alias.name.split(".")[0] for alias in node.names if alias.name != "*"}
        elif isinstance(node, ast.Try):
            names |= {handler.name for handler in node.handlers if handler.name}
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


_READING_NUMPY = ("mean", "std", "sum", "max", "min", "argmax", "argmin", "round", "array")
READ_ONLY_CALLS = frozenset(
    {
        "print", "display", "len", "str", "repr", "format", "sorted", "sum", "min", "max", "abs", "round",
        "isinstance", "type", "id", "list", "tuple", "enumerate", "zip", "range",
        *(f"{numpy}.{name}" for numpy in ("np", "numpy") for name in _READING_NUMPY),
    }
)  # fmt: skip
"""Calls that only read their arguments (with ``plt.`` / ``pyplot.`` ones): passing a value to them, as a
demo prints or plots it, changes nothing a function reads."""
_PLOTTING = ("plt.", "pyplot.", "matplotlib.")


def touched_names(statement: ast.stmt) -> set[str]:
    """Names whose object a statement may change: stored into (``P[0] = ...``, ``env.seed = 1``), deleted,
    their methods called (``env.reset()``, ``q.fill(0)``) or passed to a call that may change them
    (``np.random.shuffle(deck)``; not ``print(q)``, `READ_ONLY_CALLS`)."""
    names: set[str] = set()
    for node in ast.walk(statement):
        if isinstance(node, ast.Attribute | ast.Subscript) and isinstance(node.ctx, ast.Store | ast.Del):
            names.add(_root_name(node))
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Del):
            names.add(node.id)
        elif isinstance(node, ast.Call):
            if isinstance(node.func, ast.Attribute):
                names.add(_root_name(node.func.value))
            called = rules.dotted_name(node.func) or ""
            if called in READ_ONLY_CALLS or called.startswith(_PLOTTING):
                continue
            for argument in [*node.args, *(keyword.value for keyword in node.keywords)]:
                if isinstance(argument, ast.Starred):
                    argument = argument.value
                names.add(_root_name(argument))
    names.discard("")
    return names


def _root_name(node: ast.expr) -> str:
    while isinstance(node, ast.Attribute | ast.Subscript):
        node = node.value
    return node.id if isinstance(node, ast.Name) else ""


def globals_needed(source: str, graded: Collection[str]) -> set[str]:
    """The module-level names the ``graded`` functions use when called: their own names, the globals their
    bodies read (through the top-level functions and classes they reach, found with ``symtable``), and the
    names their defaults and decorators were made of."""
    module = symtable.symtable(source, "script", "exec")
    reads: dict[str, set[str]] = {}
    for child in module.get_children():
        if child.get_type() in ("function", "class"):
            reads.setdefault(child.get_name(), set()).update(_globals_read(child))
    for statement in parsing.parse(source).body:
        if isinstance(statement, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            made_of: list[ast.expr | None] = [*statement.decorator_list]
            if not isinstance(statement, ast.ClassDef):
                made_of += [*statement.args.defaults, *statement.args.kw_defaults]
            else:
                made_of += [*statement.bases, *(keyword.value for keyword in statement.keywords)]
            reads.setdefault(statement.name, set()).update(
                node.id
                for part in made_of
                if part is not None
                for node in ast.walk(part)
                if isinstance(node, ast.Name)
            )
    needed = set(graded)
    frontier = [name for name in graded if name in reads]
    while frontier:
        for name in reads[frontier.pop()]:
            if name not in needed:
                needed.add(name)
                if name in reads:
                    frontier.append(name)
    return needed


def unbound_globals(
    source: str, skipped_bindings: dict[str, SkippedCode], graded: Collection[str] | None
) -> list[UnboundGlobal]:
    """For each graded top-level function, the skipped-only globals its body reads, directly or via calls.

    One walk of the module collects what each top-level function and class reads (time linear in the
    source); then one graph search per graded function (a handful), so a notebook of thousands of
    functions costs a few passes over them, not one per function.
    """
    module = symtable.symtable(source, "notebook", "exec")
    reads: dict[str, set[str]] = {}  # top-level functions and classes (a class reads what its methods read)
    functions: list[str] = []
    for child in module.get_children():
        if child.get_type() in ("function", "class"):
            reads[child.get_name()] = set(_globals_read(child))
            if child.get_type() == "function":
                functions.append(child.get_name())
    chosen = sorted(set(functions) if graded is None else set(functions) & set(graded))
    entries: list[UnboundGlobal] = []
    for function in chosen:
        reachable, frontier = {function}, [function]
        missing: set[str] = set()
        while frontier:
            for name in reads[frontier.pop()]:
                if name in skipped_bindings:
                    missing.add(name)
                if name in reads and name not in reachable:
                    reachable.add(name)
                    frontier.append(name)
        for name in sorted(missing)[:MAX_NOTED_GLOBALS]:
            where = skipped_bindings[name]
            entries.append(
                UnboundGlobal(
                    function=function,
                    name=name,
                    cell=where.cell,
                    line=where.line,
                    code=where.code,
                    broken_cell=where.reason.endswith(_BROKEN) or _BROKEN + " (" in where.reason,
                )
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


def _segment(lines: list[str], node: ast.expr) -> str:
    chunk = lines[node.lineno - 1 : (node.end_lineno or node.lineno)]
    chunk[-1] = chunk[-1][: node.end_col_offset]
    chunk[0] = chunk[0][node.col_offset :]
    return "\n".join(chunk)


def _statement_text(lines: list[str], statement: ast.stmt, dropped: list[ast.expr] = ()) -> str:  # type: ignore[assignment]
    """The statement's own source: from its first decorator or column to its end, comments inside kept;
    dropped decorators left out."""
    first, last = _first_line(statement), statement.end_lineno or statement.lineno
    chunk = lines[first - 1 : last]
    start_column = statement.col_offset if first == statement.lineno else 0
    end_column = statement.end_col_offset
    if end_column is not None:
        chunk[-1] = chunk[-1][:end_column]
    chunk[0] = chunk[0][start_column:]
    for decorator in dropped:  # blank its lines (keeping the count, so cited lines stay right)
        for line in range(decorator.lineno, (decorator.end_lineno or decorator.lineno) + 1):
            chunk[line - first] = ""
    return "\n".join(chunk)


def _origins(
    lines: list[str], statement: ast.stmt, dropped: list[ast.expr], cell: int
) -> list[tuple[int, int] | None]:
    start = _first_line(statement)
    end = statement.end_lineno or statement.lineno
    return [(cell, line) for line in range(start, end + 1)]


def _shortened(text: str) -> str:
    first = text.strip().splitlines()[0] if text.strip() else ""
    suffix = " ..." if "\n" in text.strip() else ""
    return first[:MAX_CODE_CHARS] + (" ..." if len(first) > MAX_CODE_CHARS else suffix)
