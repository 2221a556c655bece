"""Dropping root: the child runs as an unprivileged uid with no capabilities and no-new-privileges."""

from __future__ import annotations

import os
import pwd
import shutil

from grader.sandbox.isolation.layer import LayerReport

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


class PrivilegesLayer:
    """Unprivileged uid, no capabilities, no-new-privileges."""

    name = "privileges"

    def probe(self) -> LayerReport:
        """When root, checks that `setpriv` exists; otherwise the grader's own uid is already unprivileged."""
        if not running_as_root():
            return LayerReport(
                self.name,
                True,
                f"runs as the grader's own unprivileged uid {os.geteuid()}, no-new-privileges",
            )
        if shutil.which("setpriv") is None:
            return LayerReport(
                self.name,
                False,
                "running as root and `setpriv` is missing",
                "install util-linux (`apt-get install util-linux`)",
            )
        try:
            name = pwd.getpwuid(SANDBOX_UID).pw_name
        except KeyError:
            name = "unnamed"
        return LayerReport(
            self.name, True, f"root drops to uid {SANDBOX_UID} ({name}), no capabilities, no-new-privileges"
        )
