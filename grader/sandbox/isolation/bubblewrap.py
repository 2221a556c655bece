"""Bubblewrap: every namespace unshared, a read-only minimal file system and a size-limited scratch tmpfs.

The child sees /usr (without /usr/local), the interpreter's prefix and site directories, the harness
tree at /gymgrade, its own file at /submission, a private /proc and /dev, and a tmpfs at /tmp.
"""

from __future__ import annotations

import functools
import os
import shutil
import subprocess
from pathlib import Path
from typing import TYPE_CHECKING

from grader.sandbox.isolation.filesystem import SYSTEM_DIRS, ChildView, PythonPaths
from grader.sandbox.isolation.layer import IsolationReport, LayerReport
from grader.sandbox.isolation.privileges import running_as_root

if TYPE_CHECKING:
    from grader.sandbox.isolation.launch import LaunchSpec

HARNESS_DIR = "/gymgrade"
SUBMISSION_DIR = "/submission"
SCRATCH_DIR = "/tmp"
LOCAL_DIR = "/usr/local"
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


@functools.cache
def _probe_machine() -> LayerReport:
    """Runs `true` in a sandbox like the children's to see that bwrap and its namespaces work (once)."""
    name = BubblewrapLayer.name
    binary = shutil.which("bwrap")
    if binary is None:
        return LayerReport(name, False, "bubblewrap (bwrap) is not installed", _REMEDY)
    argv = [binary, *_namespaces(), "--die-with-parent", "--clearenv"]
    argv += _system_binds()
    argv += ["--proc", "/proc", "--dev", "/dev", *_scratch(1 << 20), "--", "true"]
    try:
        result = subprocess.run(argv, capture_output=True, text=True, timeout=10, check=False)
    except (OSError, subprocess.TimeoutExpired) as error:
        return LayerReport(name, False, f"bwrap could not run ({error})", _REMEDY)
    if result.returncode != 0:
        return LayerReport(name, False, f"bwrap failed: {result.stderr.strip()}", _REMEDY)
    return LayerReport(
        name,
        True,
        "all namespaces unshared (no network, own PID space), read-only minimal file system, size-limited scratch tmpfs, die-with-parent, cleared environment",  # noqa: E501
    )


def private_view(submission_name: str) -> ChildView:
    """Where the child sees its scratch tmpfs, the harness tree and the submission inside bwrap."""
    return ChildView(SCRATCH_DIR, HARNESS_DIR, f"{SUBMISSION_DIR}/{submission_name}")


class BubblewrapLayer:
    """Namespaces (no network, own PID space), a minimal read-only file system, `--die-with-parent`."""

    name = "bubblewrap"

    def probe(self, outer: IsolationReport) -> LayerReport:
        """Whether bwrap and its namespaces work here (checked once per process)."""
        return _probe_machine()

    def apply(self, spec: LaunchSpec) -> None:
        """Gives the child its private file system and wraps it in bwrap, which clears the environment,
        sets the child's own and installs the syscall filter itself (taking that step from the bootstrap)."""
        submission_fd = os.memfd_create("gymgrade-submission", 0)
        spec.launch.pass_fds.append(submission_fd)
        os.write(submission_fd, spec.submission)
        os.lseek(submission_fd, 0, os.SEEK_SET)
        spec.provide_view(private_view(spec.submission_name))
        spec.process_env = {}
        spec.launch.signals_in_exit_status = True

        def wrapper(finished: LaunchSpec) -> list[str]:
            seccomp_fd, finished.bootstrap.seccomp_fd = finished.bootstrap.seccomp_fd, None
            return bwrap_argv(
                finished.paths,
                finished.tree,
                submission_fd=submission_fd,
                submission_name=finished.submission_name,
                seccomp_fd=seccomp_fd,
                scratch_bytes=finished.limits.scratch_bytes,
                env=finished.child_environment(),
            )

        spec.wrappers.append(wrapper)
