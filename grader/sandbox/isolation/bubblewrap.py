"""Bubblewrap: every namespace unshared, a read-only minimal file system and a size-limited scratch tmpfs.

The child sees /usr (without /usr/local), the interpreter's prefix and site directories, the harness
tree at /gymgrade, its own file at /submission, a private /proc and /dev, and a tmpfs at /tmp.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

from grader.sandbox.isolation.filesystem import PythonPaths
from grader.sandbox.isolation.layer import LayerReport
from grader.sandbox.isolation.privileges import running_as_root

HARNESS_DIR = "/gymgrade"
SUBMISSION_DIR = "/submission"
SCRATCH_DIR = "/tmp"
LOCAL_DIR = "/usr/local"
SYSTEM_DIRS = ("/usr", "/bin", "/sbin", "/lib", "/lib64", "/lib32")
_REMEDY = "install bubblewrap >= 0.8 (`apt-get install bubblewrap`) and allow user namespaces (`sysctl kernel.unprivileged_userns_clone=1`, or run as root)"  # noqa: E501


def _namespaces() -> list[str]:
    # As root, a user namespace would keep the child's host uid 0; without one, `setpriv` inside the
    # sandbox drops to a real unprivileged uid. Without root, a user namespace is what makes bwrap work.
    if running_as_root():
        return ["--unshare-ipc", "--unshare-pid", "--unshare-net", "--unshare-uts", "--unshare-cgroup-try"]
    return ["--unshare-all", "--unshare-user", "--disable-userns"]


def _system_binds() -> list[str]:
    """/usr read-only, and /bin, /lib, ... as the same symlinks or read-only binds as on the host."""
    arguments: list[str] = []
    for directory in SYSTEM_DIRS:
        if os.path.islink(directory):
            arguments += ["--symlink", os.readlink(directory), directory]
        elif os.path.isdir(directory):
            arguments += ["--ro-bind", directory, directory]
    return arguments


def _scratch(size: int) -> list[str]:
    return ["--perms", "1777", "--size", str(size), "--tmpfs", SCRATCH_DIR]


def _dirs_for(path: Path) -> list[str]:
    """Creates the parents of a bind target world-traversable (bwrap would copy /root's 0700)."""
    arguments: list[str] = []
    for parent in reversed(path.parents):
        if str(parent) != "/":
            arguments += ["--perms", "0755", "--dir", str(parent)]
    return arguments


def bwrap_argv(
    paths: PythonPaths,
    harness_tree: Path,
    *,
    submission_fd: int,
    submission_name: str,
    seccomp_fd: int | None,
    scratch_bytes: int,
    env: dict[str, str],
) -> list[str]:
    """The bwrap command prefix for one child (the interpreter command follows it).

    `submission_fd` (and `seccomp_fd`) must be passed to the bwrap process; bwrap copies the submission
    into a read-only file at ``/submission/<submission_name>``.
    """
    binary = shutil.which("bwrap") or "bwrap"
    argv = [binary, *_namespaces(), "--die-with-parent", "--new-session", "--clearenv"]
    argv += _system_binds()
    hide_local = os.path.isdir(LOCAL_DIR) and not os.path.islink(LOCAL_DIR)
    if hide_local:  # site-specific programs and data; the interpreter's directories are bound again below
        argv += ["--tmpfs", LOCAL_DIR]
    # The scratch tmpfs comes before the interpreter's directories: a virtualenv under /tmp (or anywhere
    # below it) is bound on top of it and stays visible, instead of being hidden by it.
    argv += _scratch(scratch_bytes)
    for root in paths.roots:
        argv += [*_dirs_for(root), "--ro-bind", str(root), str(root)]
    if hide_local:
        argv += ["--remount-ro", LOCAL_DIR]
    for hidden in paths.hidden:
        if hidden.is_dir():
            argv += ["--tmpfs", str(hidden), "--remount-ro", str(hidden)]
        else:
            argv += ["--ro-bind", "/dev/null", str(hidden)]
    argv += ["--ro-bind", str(harness_tree), HARNESS_DIR]
    argv += [
        "--perms",
        "0755",
        "--dir",
        SUBMISSION_DIR,
        "--perms",
        "0444",
        "--ro-bind-data",
        str(submission_fd),
        f"{SUBMISSION_DIR}/{submission_name}",
    ]
    argv += ["--proc", "/proc", "--dev", "/dev"]
    argv += ["--chdir", SCRATCH_DIR]
    for name, value in env.items():
        argv += ["--setenv", name, value]
    if seccomp_fd is not None:
        argv += ["--seccomp", str(seccomp_fd)]
    return [*argv, "--"]


class BubblewrapLayer:
    """Namespaces (no network, own PID space), a minimal read-only file system, `--die-with-parent`."""

    name = "bubblewrap"

    def probe(self) -> LayerReport:
        """Runs `true` in a sandbox like the children's to see that bwrap and its namespaces work."""
        binary = shutil.which("bwrap")
        if binary is None:
            return LayerReport(self.name, False, "bubblewrap (bwrap) is not installed", _REMEDY)
        argv = [binary, *_namespaces(), "--die-with-parent", "--clearenv"]
        argv += _system_binds()
        argv += ["--proc", "/proc", "--dev", "/dev", *_scratch(1 << 20), "--", "true"]
        try:
            result = subprocess.run(argv, capture_output=True, text=True, timeout=10, check=False)
        except (OSError, subprocess.TimeoutExpired) as error:
            return LayerReport(self.name, False, f"bwrap could not run ({error})", _REMEDY)
        if result.returncode != 0:
            return LayerReport(self.name, False, f"bwrap failed: {result.stderr.strip()}", _REMEDY)
        return LayerReport(
            self.name,
            True,
            "all namespaces unshared (no network, own PID space), read-only minimal file system, size-limited scratch tmpfs, die-with-parent, cleared environment",  # noqa: E501
        )
