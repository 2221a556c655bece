"""A cgroup per child (v1 and v2): memory, process and CPU limits, OOM detection, killing the whole tree."""

from __future__ import annotations

import contextlib
import errno
import functools
import os
import secrets
import signal
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from grader.sandbox import signalling
from grader.sandbox.host import Feature
from grader.sandbox.isolation import ownership, scope
from grader.sandbox.isolation.layer import IsolationReport, LayerReport

if TYPE_CHECKING:
    from grader.sandbox.isolation.layer import LaunchSpec

CGROUP_ROOT = Path("/sys/fs/cgroup")
CONTROLLERS = ("memory", "pids", "cpu")
JOB_PREFIX = "gymgrade-job-"
"""Job cgroups are named gymgrade-job-<grader pid>-<random>; the pid is for people to read, ownership is
the lock its grader holds on the directory (`grader.sandbox.isolation.ownership`). Directories of earlier
versions (gymgrade-<pid>-<random>, no lock) are never touched: nothing proves them abandoned."""
_CLAIM_ATTEMPTS = 50
_REMEDY = (
    "run as root, or in a delegated cgroup (e.g. `systemd-run --user --scope -p Delegate=yes gymgrade ...`)"
)
_INITIAL_PID_NAMESPACE = 0xEFFFFFFC
"""The inode of the initial PID namespace (the kernel's PROC_PID_INIT_INO)."""
_REMEDY_RO = (
    "a container's default: give it a writable, delegated cgroup (cgroup v2 with `--cgroupns=private`, or run the grader on the host); "  # noqa: E501
    "without one, memory and CPU are bounded per process (rlimits) and a child's tree is killed by its process group"  # noqa: E501
)
_JOIN_CGROUPS = 'for f do [ "$f" = -- ] && break; echo $$ > "$f" || exit 125; shift; done; shift; exec "$@"'
JOIN_FAILED_EXIT = 125
"""Exit status of the start-up wrapper when the child could not join its cgroups."""
CGROUP_RECORDS = "cgroups"
"""The kind of resource job cgroups are recorded under in a grading's scope: one record per job cgroup, a
`<version> <path>` line per hierarchy."""


@dataclass
class _Group:
    """One directory of a cgroup hierarchy that the child joins."""

    path: Path
    version: int
    controllers: tuple[str, ...]
    claim: ownership.Claim | None = field(default=None, compare=False)
    """The lock proving the job this grader's while it lives (None for a job being swept or released)."""

    def write(self, name: str, value: str) -> None:
        (self.path / name).write_text(value)

    def read(self, name: str) -> str:
        try:
            return (self.path / name).read_text()
        except OSError:
            return ""


def _own_paths() -> dict[str, str]:
    """Maps each v1 controller, and "" for the v2 hierarchy, to this process's cgroup path."""
    paths: dict[str, str] = {}
    for line in Path("/proc/self/cgroup").read_text().splitlines():
        _, names, path = line.split(":", 2)
        for name in names.split(",") if names else [""]:
            paths[name] = path
    return paths


def _v2_root() -> Path | None:
    for candidate in (CGROUP_ROOT, CGROUP_ROOT / "unified"):
        if (candidate / "cgroup.controllers").exists():
            return candidate
    return None


def _v2_available(group: Path) -> set[str]:
    try:
        return set((group / "cgroup.controllers").read_text().split())
    except OSError:
        return set()


@dataclass(frozen=True)
class Members:
    """The processes in a job as one PID namespace shows them.

    Attributes:
        visible: Their pids in this namespace.
        hidden: How many are outside this namespace (listed as 0: they have no pid here).
    """

    visible: frozenset[int]
    hidden: int = 0

    @property
    def empty(self) -> bool:
        """True when no process is left in the job."""
        return not self.visible and not self.hidden


@dataclass
class JobCgroup:
    """The cgroups (one per hierarchy) a single child runs in; `remove` after the child is gone."""

    groups: list[_Group] = field(default_factory=list)

    @property
    def procs_files(self) -> list[Path]:
        """Files the child writes its pid into before it execs (joins every group)."""
        return [group.path / "cgroup.procs" for group in self.groups]

    @property
    def limited(self) -> set[str]:
        """The controllers that limit the child."""
        return {name for group in self.groups for name in group.controllers}

    def members(self) -> Members:
        """Every process still in the job, as this process's PID namespace shows it."""
        visible: set[int] = set()
        hidden = 0
        for group in self.groups:
            listed = [int(pid) for pid in group.read("cgroup.procs").split()]
            visible.update(pid for pid in listed if pid > 0)
            hidden = max(hidden, sum(1 for pid in listed if pid <= 0))
        return Members(frozenset(visible), hidden)

    def pids(self) -> set[int]:
        """The processes still in the job that this process can see (and so signal)."""
        return set(self.members().visible)

    def oom_kills(self) -> int:
        """How many processes the kernel killed for exceeding the memory limit."""
        for group in self.groups:
            if "memory" in group.controllers:
                name = "memory.oom_control" if group.version == 1 else "memory.events"
                for line in group.read(name).splitlines():
                    key, _, value = line.partition(" ")
                    if key == "oom_kill":
                        return int(value)
        return 0

    def kill(self, timeout: float = 2.0) -> bool:
        """SIGKILLs every process in the job until it is empty; False when some survived `timeout`.

        The kernel kills the whole job where a v2 group has `cgroup.kill` (Linux 5.14), whatever PID
        namespace each process is in. Besides, each process this namespace shows is signalled through
        `grader.sandbox.signalling` (pinned by a pidfd, only while still listed here, never a pid of 0 or
        below nor the grader's own); a process the namespace hides is never signalled by number, so a
        job holding only such processes (or the grader's own), without `cgroup.kill`, is left as it is
        (False at once).
        """
        deadline = time.monotonic() + timeout
        while True:
            by_kernel = self._kill_by_kernel()
            members = self.members()
            if members.empty:
                return True
            reachable = [pid for pid in members.visible if signalling.refusal(pid) is None]
            if time.monotonic() > deadline or (not by_kernel and not reachable):
                return False
            signalling.kill_members(reachable, self.pids)
            time.sleep(0.005)

    def _kill_by_kernel(self) -> bool:
        """Writes `cgroup.kill` in every v2 group that has it; whether any write was taken."""
        taken = False
        for group in self.groups:
            if group.version == 2 and (group.path / "cgroup.kill").exists():
                try:
                    group.write("cgroup.kill", "1")
                except OSError:
                    continue
                taken = True
        return taken

    def remove(self) -> bool:
        """Kills what is left and removes the job's directories; False when something stayed behind."""
        emptied = self.kill()
        removed = True
        for group in self.groups:
            for _ in range(100):
                try:
                    group.path.rmdir()
                    break
                except FileNotFoundError:
                    break
                except OSError:
                    time.sleep(0.01)
            else:
                removed = False
        for group in self.groups:
            if group.claim is not None:
                group.claim.release()
        if removed and self.groups:
            scope.forget(CGROUP_RECORDS, self.groups[0].path.name)
        return emptied and removed


def remove_job_directories(directories: list[tuple[int, Path]]) -> bool:
    """Kills the processes in, and removes, the job cgroup directories given as (version, path).

    For cgroups whose owner is gone: the grading's scope (`grader.sandbox.isolation.scope`) and the
    sweep of stale jobs. Only directories named like job cgroups are touched.
    """
    groups = [_Group(path, version, ()) for version, path in directories if path.name.startswith(JOB_PREFIX)]
    return JobCgroup(groups).remove()


def _remove_recorded(lines: list[str]) -> None:
    """The scope's cleanup of one recorded job cgroup (its `<version> <path>` lines)."""
    directories = [line.split(" ", 1) for line in lines]
    remove_job_directories([(int(version), Path(path)) for version, path in directories])


scope.register_cleanup(CGROUP_RECORDS, _remove_recorded)


def _remove_stale(parent: Path, version: int) -> None:
    """Removes job cgroups left by grader processes that died without cleaning up (e.g. SIGKILL), killing
    any process still inside (its grader is gone).

    A job is taken for abandoned only when this process can take its directory's lock, which its grader
    holds while it lives, in whatever PID namespace either runs; the lock is kept while the job is removed.
    """
    for path in parent.glob(f"{JOB_PREFIX}*"):
        claim = ownership.claim_abandoned(path)
        if claim is not None:
            with claim:
                remove_job_directories([(version, path)])


def _make_group(parent: Path, name: str, version: int, controllers: tuple[str, ...]) -> _Group:
    """Makes and locks one job directory (again, when another grader's sweep took the empty directory
    between its `mkdir` and the lock)."""
    _remove_stale(parent, version)
    path = parent / name
    scope.record(
        CGROUP_RECORDS, name, f"{version} {path}"
    )  # before it exists: a kill right after mkdir leaves nothing
    for _ in range(_CLAIM_ATTEMPTS):
        with contextlib.suppress(FileExistsError):
            path.mkdir()
        try:
            return _Group(path, version, controllers, ownership.claim_new(path))
        except (BlockingIOError, FileNotFoundError):
            time.sleep(0.01)
    raise OSError(f"the job cgroup {path} was taken by another grader's sweep {_CLAIM_ATTEMPTS} times")


def _v2_parent(v2_root: Path, own_path: str) -> tuple[Path, tuple[str, ...]]:
    """Where to create the job in the v2 hierarchy, and the controllers it gets there.

    Below the grader's own cgroup when the controllers can be enabled there; a cgroup holding processes
    cannot hand controllers to children (the "no internal processes" rule), so otherwise, as root, below
    the hierarchy's root, which is exempt from that rule.
    """
    own = v2_root / own_path.lstrip("/")
    candidates = [own] if own == v2_root or os.geteuid() != 0 else [own, v2_root]
    for parent in candidates:
        offered = tuple(c for c in CONTROLLERS if c in _v2_available(parent))
        enabled = set((parent / "cgroup.subtree_control").read_text().split())
        try:
            missing = [c for c in offered if c not in enabled]
            if missing:
                (parent / "cgroup.subtree_control").write_text(" ".join(f"+{c}" for c in missing))
        except OSError:
            continue
        return parent, offered
    return own, ()


def create_job_cgroup(memory_bytes: int, max_pids: int, cpus: float = 1.0) -> JobCgroup:
    """Creates the cgroups for one child with its limits written.

    Uses the cgroup v2 hierarchy for each controller it offers here and the v1 hierarchy for the
    others; a v2 group is also created only to kill and track the tree when the v2 hierarchy is
    mounted without controllers (hybrid set-up).

    Raises:
        OSError: when the cgroup tree is not writable (see `CgroupLayer.probe`).
    """
    own = _own_paths()
    name = f"{JOB_PREFIX}{os.getpid()}-{secrets.token_hex(4)}"
    job = JobCgroup()
    try:
        wanted = list(CONTROLLERS)
        v2_root = _v2_root()
        if v2_root is not None and "" in own:
            v2_parent, offered = _v2_parent(v2_root, own[""])
            job.groups.append(_make_group(v2_parent, name, 2, offered))
            wanted = [c for c in wanted if c not in offered]
        for controller in wanted:
            mount = CGROUP_ROOT / controller
            if controller in own and (mount / "cgroup.procs").exists():
                job.groups.append(_make_group(mount / own[controller].lstrip("/"), name, 1, (controller,)))
        _write_limits(job, memory_bytes, max_pids, cpus)
    except OSError:
        job.remove()
        raise
    return job


def _write_limits(job: JobCgroup, memory_bytes: int, max_pids: int, cpus: float) -> None:
    period = 100_000
    for group in job.groups:
        if "memory" in group.controllers:
            if group.version == 1:
                group.write("memory.limit_in_bytes", str(memory_bytes))
                if (group.path / "memory.memsw.limit_in_bytes").exists():
                    group.write("memory.memsw.limit_in_bytes", str(memory_bytes))
            else:
                group.write("memory.max", str(memory_bytes))
                group.write("memory.swap.max", "0")
        if "pids" in group.controllers:
            group.write("pids.max", str(max_pids))
        if "cpu" in group.controllers:
            if group.version == 1:
                group.write("cpu.cfs_period_us", str(period))
                group.write("cpu.cfs_quota_us", str(int(period * cpus)))
            else:
                group.write("cpu.max", f"{int(period * cpus)} {period}")


@functools.cache
def _probe_machine() -> LayerReport:
    """Creates a throw-away job cgroup, kills a process placed in it, and removes it (once): which
    controllers can be used, and whether the job's tree can be killed from here."""
    try:
        job = create_job_cgroup(memory_bytes=1 << 30, max_pids=16)
    except OSError as error:
        if error.errno == errno.EROFS:
            return LayerReport(
                CgroupLayer.name, False, f"the cgroup tree is read-only here ({error})", _REMEDY_RO
            )
        detail = f"the cgroup tree is not writable here ({error})"
        return LayerReport(CgroupLayer.name, False, detail, _REMEDY)
    try:
        limited = job.limited
        versions = sorted({f"v{group.version}" for group in job.groups})
        killing = _kill_probe(job)
    finally:
        job.remove()
    if killing is None:
        return LayerReport(
            CgroupLayer.name,
            False,
            "a process placed in a job cgroup could not be killed from here",
            _REMEDY,
        )
    missing = [c for c in CONTROLLERS if c not in limited]
    if missing:
        return LayerReport(
            CgroupLayer.name,
            False,
            f"controllers {', '.join(missing)} are not available",
            "mount the cgroup controllers or delegate them to this user (" + _REMEDY + ")",
        )
    return LayerReport(
        CgroupLayer.name,
        True,
        f"cgroup {'+'.join(versions)}: memory, pids and cpu limited per child; the tree killed by {killing}"
        f"{_namespace_note()}",
    )


def _kill_probe(job: JobCgroup) -> str | None:
    """Places a process in `job` and kills the job: how it was killed, or None when it could not be."""
    argv = [*join_argv(job), "/bin/sh", "-c", "echo joined; exec sleep 60"]
    try:
        process = subprocess.Popen(
            argv,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
    except OSError:
        return None
    try:
        joined = process.stdout is not None and process.stdout.readline().strip() == b"joined"
        by_kernel = any(group.version == 2 and (group.path / "cgroup.kill").exists() for group in job.groups)
        if not joined or not job.kill() or process.wait(timeout=5) != -signal.SIGKILL:
            return None
    except subprocess.TimeoutExpired:
        return None
    finally:
        if process.poll() is None:
            signalling.kill_group(process.pid)
            process.wait()
        if process.stdout is not None:
            process.stdout.close()
    return "cgroup.kill" if by_kernel else "a signal to each of its processes (pinned by pidfd)"


def _namespace_note() -> str:
    """Says so when this process runs in a PID namespace other than the kernel's first (its inode)."""
    try:
        nested = os.stat("/proc/self/ns/pid").st_ino != _INITIAL_PID_NAMESPACE
    except OSError:
        return ""
    return (
        "; in a nested PID namespace: jobs owned by locks, hidden processes never signalled" if nested else ""
    )


def join_argv(job: JobCgroup) -> list[str]:
    """The outermost wrapper: a shell writes its pid into every group of `job`, then execs the rest
    (exit status `JOIN_FAILED_EXIT` when it cannot join)."""
    return ["/bin/sh", "-c", _JOIN_CGROUPS, "gymgrade-join", *map(str, job.procs_files), "--"]


class CgroupLayer:
    """Memory, process-count and CPU limits for the child's whole tree, and killing that tree."""

    name = "cgroup"
    needs: tuple[Feature, ...] = (Feature.LINUX_KERNEL,)
    guards = "memory, process-count and CPU limits on the child's whole tree"

    def probe(self, outer: IsolationReport) -> LayerReport:
        """Whether a job cgroup with every controller can be made here (checked once per process)."""
        return _probe_machine()

    def apply(self, spec: LaunchSpec) -> None:
        """Creates the child's job cgroup with its limits; the child joins it before anything else runs."""
        job = create_job_cgroup(spec.limits.memory_bytes, spec.limits.max_pids)
        spec.launch.cgroup = job
        spec.wrappers.append(lambda _spec: join_argv(job))
