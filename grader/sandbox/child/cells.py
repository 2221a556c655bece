"""Run a notebook's code cells in the child, in the submission's namespace, as Jupyter's "Run All" does.

A problem that needs the notebook's state (edition 4's `compare()` reads the tables its training cells made)
plans a call of `RUN_CELLS` before calling the function; the harness (`grader.sandbox.child.calls`) runs it
with `run_cells`. It is a call like any other: the same time limit mechanism (its own limit), the same
recorder (the cells' env steps go through the recording envs; a cells call is unrecorded, as training runs
are), its output captured. The cells run in order in the module's globals; the first cell that raises stops
the run, and the call raises `NotebookCellError` naming the cell, its line and the error.

The value returned is plain data for the judge: how long each cell took, and every Taxi Q-table the cells
left behind (globals holding a 500 x 6 array, and each table the notebook's `qlearn` or `sarsa0` returned,
with the learner and its `decay` and `N`). Learners are labelled by wrapping the notebook's `qlearn` and
`sarsa0` after the cell that defines them; the wrapper only notes what the learner returned.

With `bind` (the grader's tables, `grader.sandbox.child.binding`), no cell runs where the tables can be bound
to the globals the function called after the cells reads: the value is then ``{"bound": [...], "cells": [],
"tables": []}``. Where they cannot, the cells run as without it and the value says why (``"fallback"``).
"""

from __future__ import annotations

import functools
import inspect
import time
from collections.abc import Callable
from types import ModuleType, TracebackType
from typing import Any

from grader.sandbox.child.binding import bind_tables
from grader.sandbox.child.stubs import stub_body

RUN_CELLS = "notebook cells"
"""The function name of a cells call (not an identifier, so no student function can be meant)."""
LEARNERS = ("qlearn", "sarsa0")
"""The notebook's learners whose returned tables are labelled."""
TABLE_SHAPE = (500, 6)
"""A Taxi-v3 Q-table: one row per state, one column per action."""
MAX_TABLES = 16
"""Tables returned at most (each is 24 KB); learner outputs first, then globals in definition order."""
MAX_NAMES = 5
"""Global names listed per table."""
_MARK = "_gymgrade_learner"


class NotebookCellError(Exception):
    """Raised when a notebook cell raises: the message names the cell, the line and the error."""


class NotAttemptedError(Exception):
    """Raised before any cell runs when the function called after the cells is missing or a template stub."""


def run_cells(
    module: ModuleType,
    cells: list[dict[str, Any]],
    then: str | None = None,
    bind: dict[str, dict[str, Any]] | None = None,
) -> dict[str, Any]:
    """Run `cells` in order in `module`'s namespace and describe what they left behind.

    Args:
        module: The imported submission (its globals are the notebook's namespace).
        cells: ``{"cell": number, "source": python, "script": bool}`` each; a script runs with
            ``__name__ == "__main__"``.
        then: The function the problem calls after the cells: when the submission lacks it or it is still
            the template's stub, no cell runs (a template's training cells would cost minutes for nothing).
        bind: ``{learner: {"decay": table, "constant": table}}``: bind these to the globals `then` reads
            instead of running the cells, where binding can serve (`bind_tables`).

    Returns:
        ``{"cells": [{"cell", "seconds"}], "tables": [{"names", "learner", "decay", "N", "table"}]}``, with
        ``"fallback"`` (why nothing was bound) when `bind` was given; or, bound,
        ``{"bound": [{"name", "learner", "decay", "N", "cell", "line", "statement", "read"}], "cells": [],
        "tables": []}``.

    Raises:
        NotebookCellError: A cell raised (the run stops there, as "Run All" does).
        NotAttemptedError: `then` is missing or a stub.
        MemoryError: A cell ran out of memory (the harness reports the memory limit).
    """
    namespace = vars(module)
    if then is not None:
        _check_attempted(namespace, then)
    fallback: dict[str, str] = {}
    if bind is not None:
        bound = bind_tables(namespace, cells, bind, then or "compare")
        if isinstance(bound, list):
            return {"bound": bound, "cells": [], "tables": []}
        fallback["fallback"] = bound
    learned: dict[int, dict[str, Any]] = {}
    kept: list[Any] = []  # the learners' tables stay alive, so their ids stay theirs
    ran: list[dict[str, Any]] = []
    for entry in cells:
        number, source, script = int(entry["cell"]), str(entry["source"]), bool(entry["script"])
        filename = (module.__file__ or "<submission>") if script else f"<notebook cell {number}>"
        started = time.perf_counter()
        name = namespace.get("__name__")
        try:
            code = compile(source, filename, "exec")
            if script:
                namespace["__name__"] = "__main__"
            exec(code, namespace)
        except MemoryError:
            raise
        except BaseException as error:  # SystemExit and KeyboardInterrupt in a cell stop "Run All" too
            why = (
                f" (the cells ran because the grader's tables could not stand in for the training: {fallback['fallback']})"  # noqa: E501
                if fallback
                else ""
            )
            raise NotebookCellError(_described(number, script, filename, error) + why) from None
        finally:
            if script:
                namespace["__name__"] = name
        ran.append({"cell": number, "seconds": time.perf_counter() - started})
        _label_learners(namespace, learned, kept)
    return {"cells": ran, "tables": _tables(namespace, learned, kept), **fallback}


def _check_attempted(namespace: dict[str, Any], name: str) -> None:
    function = namespace.get(name)
    if not callable(function):
        raise NotAttemptedError(f"your notebook defines no function `{name}`, so its cells were not run")
    stub = stub_body(function)
    if stub is not None:
        raise NotAttemptedError(
            f"`{name}` is still the template's stub (its body {stub}), so the cells were not run"
        )


def _described(number: int, script: bool, filename: str, error: BaseException) -> str:
    line = _line_in(error.__traceback__, filename)
    if isinstance(error, SyntaxError) and error.filename == filename:
        line = error.lineno
    where = "your file run as a script" if script else f"cell {number}"
    at = f" (line {line})" if line is not None else ""
    text = str(error)
    return f"{where}{at} raised {type(error).__name__}{': ' + text if text else ''}"


def _line_in(tb: TracebackType | None, filename: str) -> int | None:
    """The line of the cell's deepest frame in the traceback (where the cell called what failed)."""
    line = None
    while tb is not None:
        if tb.tb_frame.f_code.co_filename == filename:
            line = tb.tb_lineno
        tb = tb.tb_next
    return line


def _label_learners(namespace: dict[str, Any], learned: dict[int, dict[str, Any]], kept: list[Any]) -> None:
    for name in LEARNERS:
        learner = namespace.get(name)
        if callable(learner) and not getattr(learner, _MARK, False):
            namespace[name] = _labelling(name, learner, learned, kept)


def _labelling(
    name: str, learner: Callable[..., Any], learned: dict[int, dict[str, Any]], kept: list[Any]
) -> Callable[..., Any]:
    try:
        signature: inspect.Signature | None = inspect.signature(learner)
    except Exception:  # not inspectable: tables are still labelled, without decay and N
        signature = None

    @functools.wraps(learner)
    def labelled(*args: Any, **kwargs: Any) -> Any:
        value = learner(*args, **kwargs)
        table = value[0] if isinstance(value, tuple) and value else value
        if _is_table(table) and len(kept) < MAX_TABLES:
            arguments: dict[str, Any] = {}
            if signature is not None:
                try:
                    bound = signature.bind(*args, **kwargs)
                    bound.apply_defaults()
                    arguments = dict(bound.arguments)
                except TypeError:
                    arguments = {}
            decay, episodes = arguments.get("decay"), arguments.get("N")
            learned[id(table)] = {
                "learner": name,
                "decay": decay if type(decay) is bool else None,
                "N": episodes if type(episodes) is int else None,
            }
            kept.append(table)
        return value

    setattr(labelled, _MARK, True)
    return labelled


def _is_table(value: Any) -> bool:
    # The type first: a module's lazy `__getattr__` (the light IPython's, matplotlib's) is never asked for
    # `shape`, which would import what the cells never used.
    if type(value).__module__ != "numpy":
        return False
    shape = getattr(value, "shape", None)
    kind = getattr(getattr(value, "dtype", None), "kind", None)
    return shape == TABLE_SHAPE and kind in ("f", "i", "u")


def _tables(namespace: dict[str, Any], learned: dict[int, dict[str, Any]], kept: list[Any]) -> list[Any]:
    import numpy as np

    names: dict[int, list[str]] = {}
    found: dict[int, Any] = {id(table): table for table in kept}
    for name, value in list(namespace.items()):
        if isinstance(name, str) and not name.startswith("__") and _is_table(value):
            found.setdefault(id(value), value)
            names.setdefault(id(value), []).append(name)
    tables = []
    for identity, table in list(found.items())[:MAX_TABLES]:
        values = np.array(table, dtype=np.float64)
        if not np.all(np.isfinite(values)):
            continue
        label = learned.get(identity, {"learner": None, "decay": None, "N": None})
        tables.append({"names": names.get(identity, [])[:MAX_NAMES], **label, "table": values})
    return tables
