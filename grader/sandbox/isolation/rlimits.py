"""Kernel resource limits applied by the child's bootstrap to itself before any student code runs."""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from grader.sandbox.host import HOST, Feature
from grader.sandbox.isolation.layer import IsolationReport, LayerReport
from grader.sandbox.isolation.privileges import running_as_root
from grader.sandbox.limits import Limits

if TYPE_CHECKING:
    from grader.sandbox.isolation.layer import LaunchSpec

CPU_GRACE_SECONDS = 5
"""Between the soft CPU limit (SIGXCPU) and the hard one (SIGKILL)."""


def rlimit_table(
    limits: Limits, *, dropped_uid: bool, own_user_namespace: bool
) -> list[tuple[str, int, int]]:
    """The (name, soft, hard) rlimits for a child.

    RLIMIT_NPROC counts the processes of the child's uid within its user namespace and the namespaces
    above it. In a user namespace of its own (bubblewrap without root) it counts only the child's tree, so
    it is set to `max_pids`; for the dedicated uid of a root grader it is a backstop shared by concurrent
    children (the cgroup's pids limit is the per-child one); otherwise (the grader's own uid, shared with
    the user's other programs) it is not set.
    """
    table = [
        ("RLIMIT_CPU", limits.cpu_seconds, limits.cpu_seconds + CPU_GRACE_SECONDS),
        ("RLIMIT_AS", limits.memory_bytes, limits.memory_bytes),
        ("RLIMIT_FSIZE", limits.file_bytes, limits.file_bytes),
        ("RLIMIT_NOFILE", limits.open_files, limits.open_files),
        ("RLIMIT_CORE", 0, 0),
    ]
    if own_user_namespace:
        table.append(("RLIMIT_NPROC", limits.max_pids, limits.max_pids))
    elif dropped_uid:
        table.append(("RLIMIT_NPROC", limits.max_pids * 16, limits.max_pids * 16))
    return table


class RlimitsLayer:
    """CPU time, address space, file size, open files and core dumps, set by the child on itself."""

    name = "rlimits"
    needs: tuple[Feature, ...] = (Feature.RESOURCE_LIMITS,)
    guards = "the CPU-time, memory, file-size and open-file limits"

    def probe(self, outer: IsolationReport) -> LayerReport:
        """Checks that the resource module offers every limit used."""
        resource = importlib.import_module("resource")
        table = rlimit_table(Limits(), dropped_uid=True, own_user_namespace=False)
        missing = [name for name, _, _ in table if not hasattr(resource, name)]
        if missing:
            return LayerReport(
                self.name,
                False,
                f"this system lacks {', '.join(missing)}",
                "grade on Linux, where every limit exists",
            )
        if not HOST.has(Feature.LINUX_KERNEL):
            return LayerReport(
                self.name,
                True,
                f"CPU time, file size, open files, no core dumps; the address-space limit is asked for, but {HOST.system} may not enforce it (a limit it refuses is named on the child's stderr)",  # noqa: E501
            )
        return LayerReport(self.name, True, "CPU time, address space, file size, open files, no core dumps")

    def apply(self, spec: LaunchSpec) -> None:
        """Asks the bootstrap to set the limits; RLIMIT_NPROC depends on the uid and user namespace the
        privileges and bubblewrap layers give the child."""
        root = running_as_root()
        spec.bootstrap.rlimits = rlimit_table(
            spec.limits,
            dropped_uid=root and spec.isolation.is_active("privileges"),
            own_user_namespace=spec.isolation.is_active("bubblewrap") and not root,
        )
