"""One directory per grading holding everything its sandboxes leave on the host, removed when it ends.

A grading's pytest run is SIGKILLed when its results are in or when it is abandoned, so its workers'
exit handlers never run. Instead, the grading's top-level process opens a `sandbox_scope`: every
harness tree and scratch directory of its workers is created inside the scope's directory (named by
the `SCOPE_VARIABLE` environment variable the workers inherit), and every resource outside it (a job
cgroup) is recorded there before it is created, under the kind of resource it is. Closing the scope
runs each kind's cleanup on what is still recorded, then deletes the directory.

The scope knows no layer: a layer that records a kind registers its cleanup (`register_cleanup`) when
its module is imported, which importing this package does (`grader.sandbox.isolation` lists every layer).

In detail:

- **No leftovers.** `grader.grading.grade.grade_files` opens a `grader.sandbox.isolation.scope.sandbox_scope`:
  a directory named to the session's xdist workers by `GYMGRADE_SANDBOX_SCOPE` (set in `os.environ` for the
  session only), holding every harness tree and scratch dir of its workers and a record of every job cgroup
  (written before the cgroup is made, under the kind `cgroups` whose cleanup `cgroup.py` registers with the
  scope). Closing it (after the session's workers are SIGKILLed) runs each registered cleanup (kills what is
  left in those cgroups and removes them) and removes the directory. Outside a grading, trees go to the temp
  dir (removed at exit; trees and cgroups of dead graders are swept when the next sandbox starts).
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

SCOPE_VARIABLE = "GYMGRADE_SANDBOX_SCOPE"
"""Environment variable naming the directory of the grading this process works for."""
SCOPE_PREFIX = "gymgrade-scope-"
Cleanup = Callable[[list[str]], None]
"""Releases (best effort) what one record lists: the lines recorded for one resource."""
CLEANUPS: dict[str, Cleanup] = {}
"""Every kind of resource a scope releases, with its cleanup; filled by the layers' modules on import."""


def scope_directory() -> Path | None:
    """The directory of the grading this process works for, or None outside a grading."""
    value = os.environ.get(SCOPE_VARIABLE)
    return Path(value) if value and Path(value).is_dir() else None


def temp_root() -> Path:
    """Where to create harness trees and scratch directories: the grading's scope, else the temp dir."""
    return scope_directory() or Path(tempfile.gettempdir())


def register_cleanup(kind: str, cleanup: Cleanup) -> None:
    """Makes closing a scope run `cleanup` on every resource of `kind` still recorded in it."""
    CLEANUPS[kind] = cleanup


def record(kind: str, name: str, line: str) -> None:
    """Notes, before it is created, a resource of `kind` the scope must release (no-op outside one)."""
    scope = scope_directory()
    if scope is None:
        return
    records = scope / kind
    records.mkdir(exist_ok=True)
    with (records / name).open("a", encoding="utf-8") as recorded:
        recorded.write(f"{line}\n")


def forget(kind: str, name: str) -> None:
    """Drops the record of a resource its owner released."""
    scope = scope_directory()
    if scope is not None:
        with contextlib.suppress(OSError):
            (scope / kind / name).unlink()


@contextlib.contextmanager
def sandbox_scope() -> Iterator[dict[str, str]]:
    """Opens a scope for one grading; yields the environment variables its processes must inherit.

    On exit (also after an exception), every resource still recorded is released by its kind's cleanup
    (a job cgroup is emptied with SIGKILL and removed), then the directory with every harness tree and
    scratch directory in it is deleted.
    """
    root = Path(tempfile.mkdtemp(prefix=SCOPE_PREFIX))
    os.chmod(root, 0o711)  # a child whose uid was dropped must reach its scratch inside
    try:
        yield {SCOPE_VARIABLE: str(root)}
    finally:
        release_recorded(root)
        shutil.rmtree(root, ignore_errors=True)


def release_recorded(root: Path) -> None:
    """Runs each kind's cleanup on every resource still recorded in the scope `root`."""
    for kind, cleanup in sorted(CLEANUPS.items()):
        for recorded in sorted((root / kind).glob("*")):
            with contextlib.suppress(OSError, ValueError):
                cleanup([line for line in recorded.read_text(encoding="utf-8").splitlines() if line])
