"""One directory per grading holding everything its sandboxes leave on the host, removed when it ends.

A grading's pytest run is SIGKILLed when its results are in or when it is abandoned, so its workers'
exit handlers never run. Instead, the grading's top-level process opens a `sandbox_scope`: every
harness tree and scratch directory of its workers is created inside the scope's directory (named by
the `SCOPE_VARIABLE` environment variable the workers inherit), and every job cgroup is recorded
there before it is created. Closing the scope kills what is left in those cgroups, removes them and
deletes the directory.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

SCOPE_VARIABLE = "GYMGRADE_SANDBOX_SCOPE"
"""Environment variable naming the directory of the grading this process works for."""
SCOPE_PREFIX = "gymgrade-scope-"
CGROUP_RECORDS = "cgroups"
"""Subdirectory of the scope: one file per job cgroup, a `<version> <path>` line per hierarchy."""


def scope_directory() -> Path | None:
    """The directory of the grading this process works for, or None outside a grading."""
    value = os.environ.get(SCOPE_VARIABLE)
    return Path(value) if value and Path(value).is_dir() else None


def temp_root() -> Path:
    """Where to create harness trees and scratch directories: the grading's scope, else the temp dir."""
    return scope_directory() or Path(tempfile.gettempdir())


def record_cgroup(name: str, version: int, path: Path) -> None:
    """Notes, before it is created, a job cgroup directory the scope must remove (no-op outside one)."""
    scope = scope_directory()
    if scope is None:
        return
    records = scope / CGROUP_RECORDS
    records.mkdir(exist_ok=True)
    with (records / name).open("a") as record:
        record.write(f"{version} {path}\n")


def forget_cgroup(name: str) -> None:
    """Drops the record of a job cgroup its owner removed."""
    scope = scope_directory()
    if scope is not None:
        with contextlib.suppress(OSError):
            (scope / CGROUP_RECORDS / name).unlink()


@contextlib.contextmanager
def sandbox_scope() -> Iterator[dict[str, str]]:
    """Opens a scope for one grading; yields the environment variables its processes must inherit.

    On exit (also after an exception), every recorded job cgroup still present is emptied (SIGKILL) and
    removed, then the directory with every harness tree and scratch directory in it.
    """
    root = Path(tempfile.mkdtemp(prefix=SCOPE_PREFIX))
    os.chmod(root, 0o711)  # a child whose uid was dropped must reach its scratch inside
    try:
        yield {SCOPE_VARIABLE: str(root)}
    finally:
        remove_recorded_cgroups(root)
        shutil.rmtree(root, ignore_errors=True)


def remove_recorded_cgroups(root: Path) -> None:
    """Kills the processes of, and removes, every job cgroup recorded in the scope `root`."""
    from grader.sandbox.isolation.cgroup import remove_job_directories  # the cgroup layer records here

    for record in sorted((root / CGROUP_RECORDS).glob("*")):
        with contextlib.suppress(OSError, ValueError):
            lines = [line.split(" ", 1) for line in record.read_text().splitlines() if line]
            remove_job_directories([(int(version), Path(path)) for version, path in lines])
