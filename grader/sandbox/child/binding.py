"""Bind the grader's Taxi tables to the globals a function reads, in place of the notebook's training.

Edition 4's `compare()` takes no arguments: it plays the tables the notebook's training cells left in its
globals. Its verdict does not depend on what the training learned (the judge identifies each table from the
greedy episodes and knows its exact greedy return), so the grader gives it tables of its own instead of
retraining for minutes (`grader.lab.checks.compare_tables`). `bind_tables` decides, from the function's code
and the file's own statements, which globals to bind and to which table; it runs in the child, before the
function is called, and binds nothing (returning why) where binding cannot stand in for the cells:

- **What the function reads**: the names its code object loads as globals (`LOAD_GLOBAL`), through nested
  code (comprehensions, inner functions) and the module's own functions it calls, recursively. Those the
  module does not define at import (or that hold a 500 x 6 table) are its tables.
- **Which is Q-learning's and which SARSA's**: first the file's training statements (the targets of its
  `qlearn(...)` and `sarsa0(...)` calls, in the cells or anywhere at a script's top level; the first name of a
  tuple target such as `q, pen = qlearn("Taxi-v3", decay=True)`), with the call's `decay` (a literal, or the
  learner's default); then the name (one containing "sarsa" is SARSA's, any other Q-learning's; "decay" in it
  means the decaying schedule). Every name a training statement sets is bound too (a function that reads
  them some other way, through `globals()`, finds them).
- **Not bound** (the cells run instead, as Run All would): the function calls a learner itself; it reads no
  table, or no table of one of the two learners; it reads another value a training statement returns (the
  penalties) or a global only a cell sets whose name is no table's; a statement setting a table it reads
  calls a function the file does not define (Run All stops there); a cell does not compile. A global unset at
  import, set nowhere and named like no table is left unset (the function raises NameError, as in Run All).

Each table is a fresh writable copy per (learner, schedule); names of one schedule share it.
"""

from __future__ import annotations

import ast
import builtins
import dis
import inspect
import re
import types
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any

LEARNERS = ("qlearn", "sarsa0")
"""The notebook's learners, by the names the lab's template gives them."""
MAX_CODE_OBJECTS = 2_000
"""Code objects walked at most (a module's functions and their nested code); beyond, nothing is bound."""
MAX_STATEMENT_CHARS = 120
"""A training statement is quoted in the feedback up to this length."""
_BUILTINS = frozenset(dir(builtins))
_TABLE_NAME = re.compile(r"q|table|sarsa", re.IGNORECASE)
"""A global unset at import is taken for a table when its name says so (`q_table_decay`, `Q`, `sarsa_t`)."""


@dataclass(frozen=True)
class Assignment:
    """The last statement of the file (in Run All's order) that sets a global name."""

    cell: int
    line: int
    text: str
    learner: str | None
    decay: bool | None
    episodes: int | None
    table: bool
    """The name is the table the learner returns (the target, or a tuple target's first name)."""
    callee: str | None
    """The function the statement's value calls by name, if it is a call."""


def bind_tables(
    namespace: dict[str, Any],
    cells: list[dict[str, Any]],
    tables: Mapping[str, Mapping[str, Any]],
    function: str,
) -> list[dict[str, Any]] | str:
    """Bind `tables` to the globals `function` reads, or say why binding cannot serve it.

    Args:
        namespace: The imported submission's globals.
        cells: The cells Run All would run (``{"cell", "source", "script"}``), read, never run.
        tables: ``{learner: {"decay": table, "constant": table}}``, the grader's.
        function: The function that will be called after the binding.

    Returns:
        One ``{"name", "learner", "decay", "N", "cell", "line", "statement", "read"}`` per bound name, or why
        nothing was bound (a sentence the feedback quotes).
    """
    target = namespace.get(function)
    code = getattr(target, "__code__", None)
    if not isinstance(code, types.CodeType):
        return f"{function}() is not a plain Python function, so the globals it reads cannot be read from its code"  # noqa: E501
    loaded = globals_loaded(code, namespace)
    if loaded is None:
        return f"{function}() and the functions it calls are too large to read"
    assigned = _assignments(cells, namespace)
    if isinstance(assigned, str):
        return assigned
    learners = [name for name in LEARNERS if name in loaded]
    if learners:
        return f"{function}() calls {' and '.join(f'{name}()' for name in learners)} itself, so it trains its own tables"  # noqa: E501
    others = [name for name in loaded if name in assigned and not assigned[name].table]
    if others:
        return f"{function}() reads `{others[0]}`, which the training returns besides its table, and which the grader cannot stand in for"  # noqa: E501
    unset = [name for name in loaded if _set_by_a_cell_only(name, namespace, assigned)]
    if unset:
        where = assigned[unset[0]]
        return f"{function}() reads `{unset[0]}`, which cell {where.cell} sets (line {where.line}) and which is neither a Q-table's name nor a learner's result"  # noqa: E501
    read = [name for name in loaded if _is_table_name(name, namespace, assigned)]
    if not read:
        return f"{function}() reads no global that holds or could hold a Q-table (the names its code loads are all defined at import)"  # noqa: E501
    for name in read:
        callee = assigned[name].callee if name in assigned else None
        if callee is not None and callee not in LEARNERS and not _defined(callee, namespace, assigned):
            where = assigned[name]
            return f"`{name}` is set by a call of `{callee}` (cell {where.cell}, line {where.line}), which your file does not define, so Run All would stop there"  # noqa: E501
    roles = {name: _role(name, assigned.get(name)) for name in read}
    missing = [learner for learner in LEARNERS if learner not in {role[0] for role in roles.values()}]
    if missing:
        which = "Q-learning" if missing[0] == "qlearn" else "SARSA"
        listed = ", ".join(f"`{name}`" for name in read)
        return f"{function}() reads {listed}, none of which is the {which} table (no training statement sets it and its name does not say so)"  # noqa: E501
    for name, statement in assigned.items():
        if statement.learner is not None and statement.table and name not in roles:
            roles[name] = (statement.learner, statement.decay)
    copies: dict[tuple[str, str], Any] = {}
    bound = []
    for name, (learner, decay) in roles.items():
        schedule = "constant" if decay is False else "decay"
        if (learner, schedule) not in copies:
            copies[(learner, schedule)] = tables[learner][schedule].copy()
        namespace[name] = copies[(learner, schedule)]
        entry = assigned.get(name)
        bound.append(
            {
                "name": name,
                "learner": learner,
                "decay": decay,
                "N": entry.episodes if entry else None,
                "cell": entry.cell if entry else None,
                "line": entry.line if entry else None,
                "statement": entry.text if entry and entry.learner else None,
                "read": name in read,
            }
        )
    return bound


def globals_loaded(code: types.CodeType, namespace: Mapping[str, Any]) -> list[str] | None:
    """The global names `code` loads, through nested code and the module's functions it loads (in order).

    None when more than `MAX_CODE_OBJECTS` code objects would be walked.
    """
    seen: set[int] = set()
    names: dict[str, None] = {}
    frontier = [code]
    while frontier:
        current = frontier.pop(0)
        if id(current) in seen:
            continue
        seen.add(id(current))
        if len(seen) > MAX_CODE_OBJECTS:
            return None
        for name in _loads(current):
            names.setdefault(name, None)
            value = namespace.get(name)
            if isinstance(value, types.FunctionType) and value.__globals__ is namespace:
                frontier.append(value.__code__)
        frontier.extend(const for const in current.co_consts if isinstance(const, types.CodeType))
    return list(names)


def _loads(code: types.CodeType) -> Iterator[str]:
    for instruction in dis.get_instructions(code):
        if instruction.opname in ("LOAD_GLOBAL", "LOAD_NAME") and isinstance(instruction.argval, str):
            yield instruction.argval


def _is_table_name(name: str, namespace: Mapping[str, Any], assigned: Mapping[str, Assignment]) -> bool:
    """Set by a learner's call, holding a table at import, or unset at import with a table's name."""
    if name in assigned and assigned[name].learner is not None:
        return True
    if name in namespace:
        value = namespace[name]
        return type(value).__module__ == "numpy" and getattr(value, "shape", None) == (500, 6)
    return name not in _BUILTINS and _TABLE_NAME.search(name) is not None


def _set_by_a_cell_only(name: str, namespace: Mapping[str, Any], assigned: Mapping[str, Assignment]) -> bool:
    """Unset at import, set by a statement the grader does not run, and not a table by its name."""
    return (
        name not in namespace
        and name in assigned
        and assigned[name].learner is None
        and _TABLE_NAME.search(name) is None
    )


def _defined(name: str, namespace: Mapping[str, Any], assigned: Mapping[str, Assignment]) -> bool:
    return name in namespace or name in _BUILTINS or name in assigned


def _role(name: str, entry: Assignment | None) -> tuple[str, bool | None]:
    if entry is not None and entry.learner is not None:
        return entry.learner, entry.decay
    lowered = name.lower()
    return ("sarsa0" if "sarsa" in lowered else "qlearn"), (True if "decay" in lowered else None)


def _assignments(cells: list[dict[str, Any]], namespace: Mapping[str, Any]) -> dict[str, Assignment] | str:
    """The last top-level statement setting each name, in Run All's order; why not, if a cell is broken."""
    assigned: dict[str, Assignment] = {}
    for cell in cells:
        number, source = int(cell["cell"]), str(cell["source"])
        try:
            tree = ast.parse(source)
        except (SyntaxError, ValueError, MemoryError, RecursionError):
            return f"cell {number} does not compile, so Run All would stop there"
        lines = source.splitlines()
        for statement in _top_level(tree.body):
            for name, entry in _assigned_by(statement, number, lines, namespace):
                assigned[name] = entry
    return assigned


def _top_level(body: list[ast.stmt]) -> Iterator[ast.stmt]:
    """Statements run at the top level: inside `if`, loops, `with` and `try`, not in definitions."""
    for statement in body:
        yield statement
        if isinstance(statement, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            continue
        for field in ("body", "orelse", "finalbody"):
            yield from _top_level(getattr(statement, field, []))
        for handler in getattr(statement, "handlers", []):
            yield from _top_level(handler.body)


def _assigned_by(
    statement: ast.stmt, cell: int, lines: list[str], namespace: Mapping[str, Any]
) -> Iterator[tuple[str, Assignment]]:
    if isinstance(statement, ast.Assign):
        targets, value = statement.targets, statement.value
    elif isinstance(statement, ast.AnnAssign) and statement.value is not None:
        targets, value = [statement.target], statement.value
    else:
        return
    callee = value.func.id if isinstance(value, ast.Call) and isinstance(value.func, ast.Name) else None
    learner = callee if callee in LEARNERS else None
    decay, episodes = _call_arguments(value, namespace.get(learner)) if learner else (None, None)
    text = " ".join(lines[statement.lineno - 1].split())[:MAX_STATEMENT_CHARS] if lines else ""
    for target in targets:
        names = target.elts if isinstance(target, ast.Tuple | ast.List) else [target]
        for index, element in enumerate(names):
            if isinstance(element, ast.Name):
                yield (
                    element.id,
                    Assignment(cell, statement.lineno, text, learner, decay, episodes, index == 0, callee),
                )


def _call_arguments(call: ast.expr, learner: Any) -> tuple[bool | None, int | None]:
    """The learner call's `decay` and `N`: literals bound to the learner's signature, defaults included."""
    if not isinstance(call, ast.Call) or any(isinstance(arg, ast.Starred) for arg in call.args):
        return None, None
    if any(keyword.arg is None for keyword in call.keywords):
        return None, None
    try:
        signature = inspect.signature(learner)
        keywords = {str(keyword.arg): keyword.value for keyword in call.keywords}
        bound = signature.bind(*call.args, **keywords)
        bound.apply_defaults()
    except (TypeError, ValueError):
        return None, None
    values = {name: _literal(value) for name, value in bound.arguments.items()}
    decay, episodes = values.get("decay"), values.get("N")
    return (decay if type(decay) is bool else None), (episodes if type(episodes) is int else None)


_UNKNOWN = object()


def _literal(value: Any) -> Any:
    if not isinstance(value, ast.AST):
        return value  # a default from the signature
    try:
        return ast.literal_eval(value)
    except (ValueError, TypeError, SyntaxError, MemoryError, RecursionError):
        return _UNKNOWN
