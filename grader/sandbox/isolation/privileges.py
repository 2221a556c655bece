"""Dropping root: the child runs as an unprivileged uid with no capabilities and no-new-privileges."""

from __future__ import annotations

import functools
import importlib
import os
import shutil
from typing import TYPE_CHECKING

from grader.sandbox.host import HOST, Feature
from grader.sandbox.isolation.filesystem import python_paths
from grader.sandbox.isolation.layer import IsolationReport, LayerReport

if TYPE_CHECKING:
    from grader.sandbox.isolation.layer import LaunchSpec

SANDBOX_UID = 65534
"""`nobody` on Debian and most distributions."""


def running_as_root() -> bool:
    """Whether the grader runs as root (then children must drop to `SANDBOX_UID`)."""
    return os.geteuid() == 0


def drop_argv() -> list[str]:
    """The command prefix (util-linux `setpriv`) that drops to `SANDBOX_UID` just before the interpreter."""
    setpriv = shutil.which("setpriv") or "/usr/bin/setpriv"
    return [
        setpriv,
        f"--reuid={SANDBOX_UID}",
        f"--regid={SANDBOX_UID}",
        "--clear-groups",
        "--no-new-privs",
        "--inh-caps=-all",
        "--bounding-set=-all",
        "--",
    ]


@functools.cache
def _probe_machine() -> LayerReport:
    """When root, checks that `setpriv` exists; otherwise the grader's own uid is already unprivileged."""
    layer = PrivilegesLayer.name
    if not running_as_root():
        no_new_privileges = ", no-new-privileges" if HOST.has(Feature.LINUX_KERNEL) else ""
        return LayerReport(
            layer, True, f"runs as the grader's own unprivileged uid {os.geteuid()}{no_new_privileges}"
        )
    if shutil.which("setpriv") is None:
        return LayerReport(
            layer,
            False,
            "running as root and `setpriv` is missing",
            "install util-linux (`apt-get install util-linux`)",
        )
    try:
        name = importlib.import_module("pwd").getpwuid(SANDBOX_UID).pw_name
    except KeyError:
        name = "unnamed"
    return LayerReport(
        layer, True, f"root drops to uid {SANDBOX_UID} ({name}), no capabilities, no-new-privileges"
    )


def _interpreter_readable_by_others() -> bool:
    return all(
        os.stat(root).st_mode & 0o005 == 0o005
        and all(os.stat(parent).st_mode & 0o001 for parent in root.parents)
        for root in python_paths().roots
    )


class PrivilegesLayer:
    """Unprivileged uid, no capabilities, no-new-privileges."""

    name = "privileges"
    needs: tuple[Feature, ...] = (Feature.USER_IDS,)
    guards = "a separate unprivileged user"

    def probe(self, outer: IsolationReport) -> LayerReport:
        """Whether the child can run unprivileged; as root without bubblewrap (read from `outer`), only
        if the dropped uid can still read the interpreter on the host."""
        report = _probe_machine()
        unreachable = not outer.is_active("bubblewrap") and not _interpreter_readable_by_others()
        if report.active and running_as_root() and unreachable:
            return LayerReport(
                self.name,
                False,
                "running as root without bubblewrap, and the interpreter is not readable by an unprivileged uid: "  # noqa: E501
                "the child keeps root",
                "install bubblewrap, or install Python where every user can read it",
            )
        return report

    def apply(self, spec: LaunchSpec) -> None:
        """As root, `setpriv` drops to `SANDBOX_UID` just before the interpreter (inside bwrap, if any);
        the bootstrap sets no-new-privileges for every child as its first step."""
        if running_as_root():
            spec.wrappers.append(lambda _spec: drop_argv())
