"""A pytest plugin for `bench/class_throughput.py`: logs every call the grader makes to a sandbox.

Loaded through `PYTEST_PLUGINS=class_calls` (with `bench/` on PYTHONPATH) in the grading process and in
its xdist workers. When `GYMGRADE_BENCH_CALL_LOG` names a directory, each `Sandbox.call` appends
`(file name, function, args, kwargs)` to `<pid>.pickle` there, so the bench can run the same calls
plainly. It changes nothing else (one small pickle per call: 206 for the classic lab solution).
"""

from __future__ import annotations

import os
import pickle
from pathlib import Path
from typing import Any

from grader.sandbox.runner import Sandbox

LOG_VARIABLE = "GYMGRADE_BENCH_CALL_LOG"

_directory = os.environ.get(LOG_VARIABLE)
if _directory:
    _original_call = Sandbox.call

    def _logged_call(sandbox: Sandbox, call: Any) -> Any:
        record = (sandbox._name, call.function, tuple(call.args), dict(call.kwargs))
        with (Path(_directory) / f"{os.getpid()}.pickle").open("ab") as log:
            pickle.dump(record, log)
        return _original_call(sandbox, call)

    Sandbox.call = _logged_call  # type: ignore[method-assign]


def read_calls(directory: Path) -> dict[str, list[tuple[str, tuple[Any, ...], dict[str, Any]]]]:
    """Every logged call, by submission file name (in each process's order)."""
    calls: dict[str, list[tuple[str, tuple[Any, ...], dict[str, Any]]]] = {}
    for path in sorted(directory.glob("*.pickle")):
        with path.open("rb") as log:
            while True:
                try:
                    name, function, args, kwargs = pickle.load(log)
                except EOFError:
                    break
                calls.setdefault(name, []).append((function, args, kwargs))
    return calls
