"""Composes the probed layers into the command that starts one child, and cleans up after it."""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from grader.sandbox.isolation import bubblewrap, privileges
from grader.sandbox.isolation.cgroup import JobCgroup, create_job_cgroup
from grader.sandbox.isolation.filesystem import harness_tree, python_paths
from grader.sandbox.isolation.layer import IsolationReport
from grader.sandbox.isolation.rlimits import rlimit_table
from grader.sandbox.isolation.scope import temp_root
from grader.sandbox.isolation.seccomp import compile_filter
from grader.sandbox.limits import Limits

_JOIN_CGROUPS = 'for f do [ "$f" = -- ] && break; echo $$ > "$f" || exit 125; shift; done; shift; exec "$@"'
JOIN_FAILED_EXIT = 125
"""Exit status of the start-up wrapper when the child could not join its cgroups."""


@dataclass
class Launch:
    """Everything needed to start one child and to clean up after it.

    Attributes:
        argv: The full command.
        env: The environment given to the first process of `argv`.
        pass_fds: Descriptors the first process inherits (besides the request/result pipes).
        cgroup: The child's job cgroup, when the cgroup layer is active.
        scratch: The host directory used as scratch when bubblewrap is not available.
        uses_bubblewrap: Whether the child runs under bubblewrap (its exit status then encodes signals).
        cwd: The working directory of the first process (the scratch without bubblewrap).
    """

    argv: list[str]
    env: dict[str, str]
    pass_fds: list[int] = field(default_factory=list)
    cgroup: JobCgroup | None = None
    scratch: Path | None = None
    uses_bubblewrap: bool = False
    cwd: str | None = None

    def close_descriptors(self) -> None:
        """Closes the descriptors only the child needed (call once the child has started)."""
        for descriptor in self.pass_fds:
            with contextlib.suppress(OSError):
                os.close(descriptor)
        self.pass_fds = []

    def cleanup(self) -> bool:
        """Kills whatever is left in the cgroup and removes it and the scratch; False if anything stayed."""
        self.close_descriptors()
        clean = self.cgroup.remove() if self.cgroup is not None else True
        if self.scratch is not None:
            shutil.rmtree(self.scratch, ignore_errors=True)
        return clean


def _child_env(scratch: str) -> dict[str, str]:
    return {
        "PATH": "/usr/bin:/bin",
        "HOME": scratch,
        "TMPDIR": scratch,
        "LANG": "C.UTF-8",
        "PYTHONHASHSEED": "0",
        "PYTHONDONTWRITEBYTECODE": "1",
        "MPLCONFIGDIR": f"{scratch}/.matplotlib",
    }


def build_launch(
    report: IsolationReport,
    limits: Limits,
    *,
    submission: bytes,
    submission_name: str,
    requests_fd: int,
    results_fd: int,
    import_seed: int,
) -> Launch:
    """The command starting one child with every active layer of `report` applied.

    Raises:
        OSError: when a layer that was probed as active fails now (the caller reports a sandbox error).
    """
    paths = python_paths()
    tree = harness_tree()
    use_bwrap = report.is_active("bubblewrap")
    drop_uid = privileges.running_as_root() and report.is_active("privileges")
    launch = Launch(argv=[], env={})
    try:
        if report.is_active("cgroup"):
            launch.cgroup = create_job_cgroup(limits.memory_bytes, limits.max_pids)
        seccomp_fd = compile_filter() if report.is_active("seccomp") else None
        if seccomp_fd is not None:
            launch.pass_fds.append(seccomp_fd)
        launch.uses_bubblewrap = use_bwrap
        if use_bwrap:
            submission_fd = os.memfd_create("gymgrade-submission", 0)
            launch.pass_fds.append(submission_fd)
            os.write(submission_fd, submission)
            os.lseek(submission_fd, 0, os.SEEK_SET)
            scratch = bubblewrap.SCRATCH_DIR
            harness_dir = bubblewrap.HARNESS_DIR
            submission_path = f"{bubblewrap.SUBMISSION_DIR}/{submission_name}"
            launch.env = {}
            outer = bubblewrap.bwrap_argv(
                paths,
                tree,
                submission_fd=submission_fd,
                submission_name=submission_name,
                seccomp_fd=seccomp_fd,
                scratch_bytes=limits.scratch_bytes,
                env=_child_env(scratch),
            )
            bootstrap_seccomp = None
        else:
            launch.scratch = Path(tempfile.mkdtemp(prefix="gymgrade-scratch-", dir=temp_root()))
            os.chmod(launch.scratch, 0o1777)
            submission_dir = launch.scratch / ".submission"
            submission_dir.mkdir()
            (submission_dir / submission_name).write_bytes(submission)
            os.chmod(submission_dir, 0o555)
            scratch, harness_dir = str(launch.scratch), str(tree)
            submission_path = str(submission_dir / submission_name)
            launch.env = _child_env(scratch)
            launch.cwd = scratch
            outer = []
            bootstrap_seccomp = seccomp_fd
        landlock = None
        if report.is_active("landlock") and not use_bwrap:
            read = [
                *map(str, paths.roots),
                *bubblewrap.SYSTEM_DIRS,
                str(tree),
                "/dev/null",
                "/dev/urandom",
                "/proc/self",
                "/etc/ld.so.cache",
                "/etc/localtime",
            ]
            landlock = {"read": read, "write": [scratch]}
        config = {
            "sys_path": [f"{harness_dir}/lib", *paths.stdlib, *paths.site_dirs],
            "rlimits": rlimit_table(
                limits,
                dropped_uid=drop_uid,
                own_user_namespace=use_bwrap and not privileges.running_as_root(),
            ),
            "landlock": landlock,
            "seccomp_fd": bootstrap_seccomp,
            "harness_argv": [
                "--submission",
                submission_path,
                "--requests",
                str(requests_fd),
                "--results",
                str(results_fd),
                "--max-frame",
                str(limits.frame_bytes),
                "--seed",
                str(import_seed),
            ],
        }
        inner = [str(paths.executable), "-S", "-B", f"{harness_dir}/bootstrap.py", json.dumps(config)]
        drop = privileges.drop_argv() if drop_uid else []
        join = (
            ["/bin/sh", "-c", _JOIN_CGROUPS, "gymgrade-join", *map(str, launch.cgroup.procs_files), "--"]
            if launch.cgroup is not None
            else []
        )
        launch.argv = [*join, *outer, *drop, *inner]
    except BaseException:
        launch.cleanup()
        raise
    return launch
