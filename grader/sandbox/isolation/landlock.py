"""Landlock: the file-system fallback when bubblewrap is unavailable, applied by the child to itself.

Reads are limited to the interpreter, the libraries and the harness tree, writes to the scratch
directory, (Landlock ABI >= 4) TCP bind and connect are denied, and (ABI >= 6) the child signals no
process outside its own tree: without bubblewrap's PID namespace and a dropped uid (a container's root),
`kill(-1)` would otherwise reach the grader and the other children. The system calls themselves are in
`landlock_syscalls.py` (stdlib only: the child's bootstrap loads it from the harness tree).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

from grader.sandbox.host import Feature
from grader.sandbox.isolation import landlock_syscalls
from grader.sandbox.isolation.filesystem import SYSTEM_CONFIG_DIRS, SYSTEM_DIRS
from grader.sandbox.isolation.layer import IsolationReport, LayerReport

if TYPE_CHECKING:
    from grader.sandbox.isolation.layer import LaunchSpec

READABLE_FILES = ("/dev/null", "/dev/urandom", "/proc/self", "/etc/ld.so.cache", "/etc/localtime")
"""Files outside the interpreter's directories the child reads."""


class LandlockLayer:
    """Reads limited to what the child runs, writes to its scratch (optional: bubblewrap hides more)."""

    name = "landlock"
    needs: tuple[Feature, ...] = (Feature.LINUX_KERNEL,)
    guards = "the file-system restriction"

    def probe(self, outer: IsolationReport) -> LayerReport:
        """Not needed under bubblewrap (read from `outer`); else whether this kernel offers Landlock."""
        if outer.is_active("bubblewrap"):
            return LayerReport(
                self.name, False, "not needed: bubblewrap already hides the file system", required=False
            )
        abi = landlock_syscalls.abi_version()
        if abi < 1:
            return LayerReport(
                self.name,
                False,
                "unavailable: the file system is NOT hidden from student code",
                "use Linux >= 5.13 with Landlock enabled, or install bubblewrap",
                required=False,
            )
        network = "and TCP" if abi >= 4 else "(network NOT restricted: Landlock ABI < 4)"
        signals = (
            "; no signal leaves the child's own tree"
            if abi >= landlock_syscalls.SCOPED_ABI
            else "; signals NOT scoped (Landlock ABI < 6)"
        )
        return LayerReport(
            self.name,
            True,
            f"fallback (ABI {abi}): "
            f"reads limited to the interpreter and libraries, writes to the scratch directory, {network}{signals}",  # noqa: E501
            required=False,
        )

    def apply(self, spec: LaunchSpec) -> None:
        """Asks the bootstrap to restrict the child to the paths it needs, as the child sees them."""
        view = spec.child_view()
        config = [directory for directory in SYSTEM_CONFIG_DIRS if os.path.isdir(directory)]
        read = [*map(str, spec.paths.roots), *SYSTEM_DIRS, *config, view.harness, *READABLE_FILES]
        spec.bootstrap.landlock = {"read": read, "write": [view.scratch]}
