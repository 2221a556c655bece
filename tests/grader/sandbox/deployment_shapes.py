"""The machines gymgrade is deployed on, built around one command: a PID namespace sharing the host's
cgroups, a container as Docker runs one by default, Gradescope's autograder container.

Each shape is a command prefix; nothing here needs Docker. Used by `test_deployment_shapes.py` and
`bench/deployment_shapes.py`. Every shape starts its command in a new session, so that even a grader that
signalled its own process group could not reach the caller.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
HONEST = ROOT / "submissions" / "classic_complete.py"
GYMGRADE = [sys.executable, "-m", "grader"]

PID_NAMESPACE = ("unshare", "--pid", "--fork", "--mount-proc", "--")
"""A PID namespace sharing the host's cgroups, mounts and file system (privileged containers, pods,
systemd-nspawn, CI runners): processes outside it read as 0 in `cgroup.procs`."""


def can_build_shapes() -> str | None:
    """Why the shapes cannot be built here (None when they can): they need root and util-linux."""
    if os.geteuid() != 0:
        return "deployment shapes need root (namespaces, mounts, capability bounding sets)"
    missing = [tool for tool in ("unshare", "setpriv", "mount") if shutil.which(tool) is None]
    if missing:
        return f"deployment shapes need util-linux's {', '.join(missing)}"
    return None


def run_in(
    shape: Sequence[str], argv: Sequence[str], *, cwd: Path = ROOT, timeout: float = 600
) -> subprocess.CompletedProcess[str]:
    """Runs `argv` inside `shape` in a new session; `timeout` only bounds a hang."""
    return subprocess.run(
        [*shape, *argv],
        cwd=cwd,
        capture_output=True,
        text=True,
        start_new_session=True,
        timeout=timeout,
        check=False,
    )
