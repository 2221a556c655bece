"""CPU of every process of a benchmarked run, killed ones too: a cgroup v1 `cpuacct` group it starts in.

Used by `bench/class_throughput.py` and `bench/speed.py`.
"""

from __future__ import annotations

import contextlib
import os
import time
from pathlib import Path


class CpuGroup:
    """A cgroup v1 `cpuacct` group the run starts in: its usage is every descendant's CPU, killed ones too.

    `RUSAGE_CHILDREN` misses processes whose parent died without waiting for them (the sandbox kills a
    child's whole cgroup at once); the grader makes no groups in the `cpuacct` hierarchy, so every
    process of the run stays in this one. None of this is available without cgroup v1 `cpuacct` as root:
    then `RUSAGE_CHILDREN` is used and the section says so.
    """

    ROOT = Path("/sys/fs/cgroup/cpuacct")

    def __init__(self, name: str) -> None:
        self.path: Path | None = self.ROOT / f"gymgrade-bench-{os.getpid()}-{name}"
        try:
            self.path.mkdir()
        except OSError:
            self.path = None

    def join(self) -> None:
        """Move the calling process into the group (a `preexec_fn`: runs in the child before exec)."""
        if self.path is not None:
            (self.path / "cgroup.procs").write_text(str(os.getpid()))

    def seconds(self) -> float | None:
        """CPU used by the group's processes so far, None without a group."""
        if self.path is None:
            return None
        return int((self.path / "cpuacct.usage").read_text()) / 1e9

    def remove(self) -> None:
        """Remove the group once its processes are gone (waits a few seconds for stragglers)."""
        if self.path is None:
            return
        for _ in range(50):
            with contextlib.suppress(OSError):
                self.path.rmdir()
                return
            time.sleep(0.1)
