"""Bubblewrap: every namespace unshared, a read-only minimal file system and a size-limited scratch tmpfs.

The child sees /usr (without /usr/local), the interpreter's directories (`interpreter_binds`), the harness
tree at /gymgrade, its own file at /submission, a private /proc and /dev, and a tmpfs at /tmp.

Mount order: the system directories, the tmpfs masks over /usr/local and /tmp, then each interpreter
directory not already visible read-only (ancestors first), then the hidden hooks. An interpreter directory
that lies inside the /usr bind (Debian's prefix /usr, /usr/lib/python3/dist-packages) is not bound again:
a second bind of /usr would cover the /usr/local mask and leave nothing there for bubblewrap to remount
read-only ("Can't remount readonly on /newroot/usr/local").
"""

from __future__ import annotations

import functools
import os
import shutil
import subprocess
from pathlib import Path
from typing import TYPE_CHECKING

from grader.sandbox.errors import SandboxLayoutError
from grader.sandbox.host import Feature
from grader.sandbox.isolation.filesystem import (
    SYSTEM_CONFIG_DIRS,
    SYSTEM_DIRS,
    ChildView,
    PythonPaths,
    python_paths,
)
from grader.sandbox.isolation.layer import IsolationReport, LayerReport
from grader.sandbox.isolation.privileges import running_as_root

if TYPE_CHECKING:
    from grader.sandbox.isolation.layer import LaunchSpec

HARNESS_DIR = "/gymgrade"
SUBMISSION_DIR = "/submission"
SCRATCH_DIR = "/tmp"
LOCAL_DIR = "/usr/local"
MASKED_DIRS = (LOCAL_DIR, SCRATCH_DIR)
"""Directories covered by an empty tmpfs in the sandbox (interpreter directories in them are bound again)."""
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
    for directory in SYSTEM_CONFIG_DIRS:
        if os.path.isdir(directory):
            arguments += [*_dirs_for(Path(directory), set()), "--ro-bind", directory, directory]
    return arguments


def _system_bind_targets() -> tuple[Path, ...]:
    return tuple(Path(d) for d in SYSTEM_DIRS if os.path.isdir(d) and not os.path.islink(d))


def _deepest_mount(path: Path, mounts: dict[Path, str]) -> str | None:
    covering = [mount for mount in mounts if path.is_relative_to(mount)]
    return mounts[max(covering, key=lambda mount: len(mount.parts))] if covering else None


def interpreter_binds(
    roots: tuple[Path, ...],
    system: tuple[Path, ...] = (),
    masked: tuple[Path, ...] = tuple(map(Path, MASKED_DIRS)),
) -> tuple[Path, ...]:
    """The interpreter directories to bind read-only, in mount order (ancestors first), each once.

    A directory is left out when the mount that would show it is already a read-only bind: a system
    directory (`/usr` holds Debian's prefix, stdlib and /usr/lib/python3/dist-packages) or an interpreter
    directory bound before it (a virtualenv's site-packages inside the virtualenv). One under a mask
    (/usr/local, /tmp) is bound again on top of the mask.

    Args:
        roots: The interpreter's directories (`PythonPaths.roots`), resolved.
        system: The system directories bound read-only before them (`SYSTEM_DIRS` that are directories).
        masked: The directories covered by an empty tmpfs before them.

    Raises:
        SandboxLayoutError: a directory contains a system directory, a mask or the scratch /tmp (a Python
            installed at / or at /tmp), so binding it would undo them.
    """
    mounts: dict[Path, str] = {path: "bind" for path in system}
    mounts.update({path: "mask" for path in masked})
    binds: list[Path] = []
    for root in sorted(set(roots), key=lambda path: (len(path.parts), path)):
        covered = [mount for mount, kind in mounts.items() if kind == "bind" and mount.is_relative_to(root)]
        covered = [mount for mount in covered if mount != root]
        covered += [Path(SCRATCH_DIR)] if Path(SCRATCH_DIR).is_relative_to(root) else []
        if covered:
            raise SandboxLayoutError(
                f"the interpreter directory {root} contains {covered[0]}, which the sandbox replaces or hides; "  # noqa: E501
                "binding it read-only would undo that: install Python under a prefix of its own (a virtualenv, pyenv, /opt/python) and run gymgrade from there"  # noqa: E501
            )
        if _deepest_mount(root, mounts) == "bind":
            continue
        mounts[root] = "bind"
        binds.append(root)
    return tuple(binds)


def _scratch(size: int) -> list[str]:
    return ["--perms", "1777", "--size", str(size), "--tmpfs", SCRATCH_DIR]


def _dirs_for(path: Path, created: set[str]) -> list[str]:
    """Creates the parents of a bind target world-traversable (bwrap would copy /root's 0700), once each."""
    arguments: list[str] = []
    for parent in reversed(path.parents):
        if str(parent) != "/" and str(parent) not in created:
            created.add(str(parent))
            arguments += ["--perms", "0755", "--dir", str(parent)]
    return arguments


def file_system_argv(paths: PythonPaths, scratch_bytes: int) -> list[str]:
    """The mounts showing the child the system, the interpreter's directories and a scratch tmpfs.

    Raises:
        SandboxLayoutError: the interpreter's directories cannot be bound (`interpreter_binds`).
    """
    argv = _system_binds()
    hide_local = os.path.isdir(LOCAL_DIR) and not os.path.islink(LOCAL_DIR)
    if hide_local:  # site-specific programs and data; the interpreter's directories are bound again below
        argv += ["--tmpfs", LOCAL_DIR]
    # The scratch tmpfs comes before the interpreter's directories: a virtualenv under /tmp (or anywhere
    # below it) is bound on top of it and stays visible, instead of being hidden by it.
    argv += _scratch(scratch_bytes)
    masked = tuple(Path(d) for d in MASKED_DIRS if d != LOCAL_DIR or hide_local)
    created: set[str] = set()
    for root in interpreter_binds(paths.roots, _system_bind_targets(), masked):
        argv += [*_dirs_for(root, created), "--ro-bind", str(root), str(root)]
    if hide_local:
        argv += ["--remount-ro", LOCAL_DIR]
    for hidden in paths.hidden:
        if hidden.is_dir():
            argv += ["--tmpfs", str(hidden), "--remount-ro", str(hidden)]
        else:
            argv += ["--ro-bind", "/dev/null", str(hidden)]
    return argv


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
    argv += file_system_argv(paths, scratch_bytes)
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


_SEES_DIRECTORIES = "import os, sys; sys.exit(' '.join(p for p in sys.argv[1:] if not os.path.isdir(p)) or 0)"
"""Run by the probe's interpreter inside bwrap: exits naming each directory of its sys.path it cannot see."""
_CONTAINER_REMEDY = (
    "root may not make namespaces here: a container's default (Docker's seccomp profile, no CAP_SYS_ADMIN); "
    "allow them (`docker run --security-opt seccomp=unconfined --cap-add SYS_ADMIN`) or grade on the host"
)


def _refused_namespaces_as_root(failure: str) -> bool:
    """Whether bwrap, run as root, was refused its namespaces (a container, not a missing sysctl)."""
    return os.geteuid() == 0 and "namespace" in failure and "Operation not permitted" in failure


_LAYOUT_REMEDY = "run `gymgrade doctor` and report its output; meanwhile install gymgrade in a virtualenv of a Python under its own prefix (pyenv, /opt/...)"  # noqa: E501


def without_new_root(text: str) -> str:
    """bwrap's message with its own mount point taken out, so that it names the host's path."""
    return text.strip().replace("/newroot/", "/").replace('"/newroot"', '"/"')


def _run(argv: list[str]) -> subprocess.CompletedProcess[str] | str:
    try:
        return subprocess.run(argv, capture_output=True, text=True, timeout=20, check=False)
    except (OSError, subprocess.TimeoutExpired) as error:
        return f"bwrap could not run ({error})"


def _probe_interpreter(binary: str) -> str | None:
    """Why the interpreter cannot start in the child's file system, or None when it can."""
    paths = python_paths()
    try:
        mounts = file_system_argv(paths, 1 << 20)
    except SandboxLayoutError as error:
        return str(error)
    wanted = [*paths.stdlib, *paths.site_dirs]
    wanted = [directory for directory in wanted if os.path.isdir(directory)]
    argv = [binary, *_namespaces(), "--die-with-parent", "--clearenv", *mounts]
    argv += ["--dev", "/dev", "--proc", "/proc"]
    result = _run([*argv, "--", str(paths.executable), "-S", "-c", _SEES_DIRECTORIES, *wanted])
    if isinstance(result, str):
        return result
    if result.returncode == 0:
        return None
    message = without_new_root(result.stderr)
    if not message.startswith("bwrap:"):
        message = f"{paths.executable} started but cannot see these directories of its sys.path: {message}"
    return f"the child's file system could not be built from the interpreter's directories: {message}"


@functools.cache
def _probe_machine() -> LayerReport:
    """Runs `true`, then the interpreter, in a sandbox like the children's (once): bwrap and its namespaces
    work, and the interpreter's directories can be bound and are all visible to it."""
    name = BubblewrapLayer.name
    binary = shutil.which("bwrap")
    if binary is None:
        return LayerReport(name, False, "bubblewrap (bwrap) is not installed", _REMEDY)
    argv = [binary, *_namespaces(), "--die-with-parent", "--clearenv"]
    argv += _system_binds()
    result = _run([*argv, "--proc", "/proc", "--dev", "/dev", *_scratch(1 << 20), "--", "true"])
    if isinstance(result, str):
        return LayerReport(name, False, result, _REMEDY)
    if result.returncode != 0:
        failure = without_new_root(result.stderr)
        remedy = _CONTAINER_REMEDY if _refused_namespaces_as_root(failure) else _REMEDY
        return LayerReport(name, False, f"bwrap failed: {failure}", remedy)
    problem = _probe_interpreter(binary)
    if problem is not None:
        return LayerReport(name, False, problem, _LAYOUT_REMEDY)
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
    needs: tuple[Feature, ...] = (Feature.LINUX_KERNEL,)
    guards = "a private read-only file system, no network"

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
