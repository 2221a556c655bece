"""Isolation layers: what the child can and cannot do with every layer, and with each fallback."""

from __future__ import annotations

import errno
import importlib.util
import signal
import socket
import subprocess
import tempfile
import textwrap
import time
from pathlib import Path

import pytest

from grader.sandbox import (
    Call,
    IsolationPolicy,
    IsolationReport,
    IsolationUnavailable,
    LayerReport,
    Limits,
    OutcomeStatus,
    Sandbox,
    probe_isolation,
)
from grader.sandbox.isolation import landlock_syscalls, ownership
from grader.sandbox.isolation.cgroup import JOB_PREFIX, create_job_cgroup
from grader.sandbox.isolation.filesystem import TREE_PREFIX, harness_tree, python_paths, remove_stale_trees
from grader.sandbox.isolation.privileges import SANDBOX_UID, running_as_root
from grader.sandbox.isolation.rlimits import rlimit_table

ROOT = Path(__file__).resolve().parents[3]
LIMITS = Limits(call_seconds=2, import_seconds=6)
CHILD_ENVIRONMENT = {
    "HOME",
    "LANG",
    "MKL_NUM_THREADS",
    "MPLBACKEND",
    "MPLCONFIGDIR",
    "OMP_NUM_THREADS",
    "OPENBLAS_NUM_THREADS",
    "PATH",
    "PWD",
    "PYGAME_HIDE_SUPPORT_PROMPT",
    "PYTHONDONTWRITEBYTECODE",
    "PYTHONHASHSEED",
    "PYTHONUTF8",
    "SDL_AUDIODRIVER",
    "SDL_VIDEODRIVER",
    "TMPDIR",
}
PROBE = textwrap.dedent("""
    import ctypes
    import os
    import socket
    import tempfile


    def _errno(action):
        try:
            action()
        except OSError as error:
            return error.errno
        return 0


    def _connect(port):
        with socket.create_connection(("127.0.0.1", port), timeout=1):
            pass


    def probe(project_root, outside, port):
        libc = ctypes.CDLL(None, use_errno=True)
        scratch = os.path.join(tempfile.gettempdir(), "scratch.txt")
        config = os.path.join(project_root, "grader", "lab", "assignment.toml")
        return {
            "inet": _errno(lambda: socket.socket(socket.AF_INET, socket.SOCK_STREAM).close()),
            "unix": _errno(lambda: socket.socket(socket.AF_UNIX, socket.SOCK_STREAM).close()),
            "connect": _errno(lambda: _connect(port)),
            "unshare": 0 if libc.unshare(0x10000000) == 0 else ctypes.get_errno(),
            "uid": os.getuid(),
            "cwd_is_scratch": os.getcwd() == tempfile.gettempdir(),
            "reference": _errno(lambda: open(os.path.join(project_root, "reference", "__init__.py")).close()),
            "config": _errno(lambda: open(config).close()),
            "write_outside": _errno(lambda: open(outside, "w").close()),
            "write_scratch": _errno(lambda: open(scratch, "w").close()),
            "environment": sorted(os.environ),
        }


    def spin():
        while True:
            pass


    def ok():
        return 42
""")

FULL = probe_isolation()
pytestmark = pytest.mark.sandbox
needs_full = pytest.mark.skipif(not FULL.full, reason="needs full isolation:\n" + FULL.summary())


@pytest.fixture
def submission(tmp_path: Path) -> Path:
    path = tmp_path / "probe.py"
    path.write_text(PROBE)
    return path


@needs_full
def test_full_isolation_denies_network_namespaces_project_files_and_secrets(
    submission: Path, tmp_path: Path
) -> None:
    with (
        Sandbox(submission, seed=0, limits=LIMITS) as sandbox,
        socket.create_server(("127.0.0.1", 0)) as server,
    ):
        seen = sandbox.call(
            Call("probe", (str(ROOT), str(tmp_path / "outside.txt"), server.getsockname()[1]))
        ).value
    assert seen["inet"] == errno.EAFNOSUPPORT
    assert seen["unix"] == 0
    assert seen["connect"] == errno.EAFNOSUPPORT
    assert seen["unshare"] == errno.EPERM
    assert seen["reference"] == errno.ENOENT and seen["config"] == errno.ENOENT
    assert seen["write_outside"] != 0 and seen["write_scratch"] == 0
    assert set(seen["environment"]) <= CHILD_ENVIRONMENT
    if running_as_root():
        assert seen["uid"] == SANDBOX_UID
    assert not (tmp_path / "outside.txt").exists()


FALLBACKS = [
    ("no cgroup", ("cgroup",)),
    ("no bubblewrap, landlock", ("bubblewrap",)),
    ("no seccomp", ("seccomp",)),
    ("landlock only", ("cgroup", "bubblewrap", "seccomp")),
    ("rlimits only", ("cgroup", "bubblewrap", "seccomp", "landlock")),
    ("rlimits only, as the grader's uid", ("cgroup", "bubblewrap", "seccomp", "landlock", "privileges")),
]


@needs_full
@pytest.mark.parametrize("disabled", [case[1] for case in FALLBACKS], ids=[case[0] for case in FALLBACKS])
def test_each_fallback_still_runs_times_out_and_states_what_is_missing(
    submission: Path, tmp_path: Path, disabled: tuple[str, ...]
) -> None:
    report = probe_isolation(frozenset(disabled))
    with (
        Sandbox(
            submission, seed=0, limits=LIMITS, policy=IsolationPolicy.ALLOW_FALLBACK, isolation=report
        ) as sandbox,
        socket.create_server(("127.0.0.1", 0)) as server,
    ):
        server.settimeout(0)
        seen = sandbox.call(
            Call("probe", (str(ROOT), str(tmp_path / "outside.txt"), server.getsockname()[1]))
        )
        timed_out = sandbox.call(Call("spin"))
        following = sandbox.call(Call("ok"))
    assert seen.status is OutcomeStatus.OK, seen.message + seen.stderr
    assert timed_out.status is OutcomeStatus.TIMEOUT
    assert following.value == 42
    assert {layer.name for layer in sandbox.isolation.missing} >= set(disabled) - {"landlock"}
    hidden = "bubblewrap" not in disabled or report.is_active("landlock")
    assert (seen.value["reference"] != 0) == hidden
    assert (seen.value["inet"] == errno.EAFNOSUPPORT) == ("seccomp" not in disabled)
    landlock_tcp = report.is_active("landlock") and landlock_syscalls.abi_version() >= 4
    network_closed = not {"bubblewrap", "seccomp"} <= set(disabled) or landlock_tcp
    assert (seen.value["connect"] != 0) == network_closed, "only rlimits-only fallbacks reach the network"
    assert seen.value["write_scratch"] == 0
    assert seen.value["cwd_is_scratch"]
    assert (tmp_path / "outside.txt").exists() == (not hidden), (
        "only the rlimits-only fallback lets writes out"
    )


def test_require_full_fails_closed_naming_the_missing_layer_and_its_remedy(submission: Path) -> None:
    report = IsolationReport(
        (
            LayerReport(
                "bubblewrap", False, "bubblewrap (bwrap) is not installed", "apt-get install bubblewrap"
            ),
            LayerReport("rlimits", True, "CPU time, address space"),
        )
    )
    with pytest.raises(IsolationUnavailable) as raised:
        Sandbox(submission, seed=0, limits=LIMITS, policy=IsolationPolicy.REQUIRE_FULL, isolation=report)
    message = str(raised.value)
    assert "- bubblewrap: bubblewrap (bwrap) is not installed; to fix: apt-get install bubblewrap" in message
    assert "IsolationPolicy.ALLOW_FALLBACK" in message


REPORTS = [
    ("all active", (True, True), True, []),
    ("required missing", (False, True), False, ["cgroup"]),
    ("optional missing", (True, False), True, []),
]


@pytest.mark.parametrize(
    ("active", "full", "missing"), [case[1:] for case in REPORTS], ids=[case[0] for case in REPORTS]
)
def test_report_is_full_only_when_every_required_layer_is_active(
    active: tuple[bool, bool], full: bool, missing: list[str]
) -> None:
    report = IsolationReport(
        (
            LayerReport("cgroup", active[0], "limits", "delegate"),
            LayerReport("landlock", active[1], "fallback", "kernel", required=False),
        )
    )
    assert report.full is full
    assert [layer.name for layer in report.missing] == missing
    assert report.to_dict()["full"] is full
    assert report.summary().splitlines()[0] == (
        "[x] cgroup: limits" if active[0] else "[ ] cgroup: limits -- delegate"
    )


def test_probe_reports_every_layer_with_a_remedy_when_inactive() -> None:
    report = probe_isolation()
    assert [layer.name for layer in report.layers] == [
        "cgroup",
        "bubblewrap",
        "seccomp",
        "privileges",
        "rlimits",
        "landlock",
    ]
    assert all(layer.remedy or layer.active or not layer.required for layer in report.layers)


def test_switching_off_an_unknown_layer_is_refused() -> None:
    with pytest.raises(ValueError, match="unknown isolation layers \\['firewall'\\]"):
        probe_isolation(frozenset({"firewall"}))


@pytest.mark.skipif(not FULL.is_active("cgroup"), reason="the cgroup tree is not writable here")
def test_a_job_cgroup_limits_kills_and_removes_its_whole_tree() -> None:
    job = create_job_cgroup(memory_bytes=1536 << 20, max_pids=8)
    script = 'for f do echo $$ > "$f"; done; sleep 60 & sleep 60 & wait'
    shell = subprocess.Popen(["/bin/sh", "-c", script, "join", *map(str, job.procs_files)])
    try:
        deadline = time.monotonic() + 120  # bounds a hang only: the loop ends when all three joined
        while len(job.pids()) < 3 and time.monotonic() < deadline:
            time.sleep(0.01)
        assert len(job.pids()) == 3
        assert job.limited == {"memory", "pids", "cpu"}
        assert job.kill()
        assert job.pids() == set()
    finally:
        removed = job.remove()
        shell.wait(timeout=5)
    assert removed
    assert not any(group.path.exists() for group in job.groups)
    assert shell.returncode == -signal.SIGKILL


NPROC = [
    ("own user namespace", False, True, LIMITS.max_pids),
    ("dropped uid, shared", True, False, LIMITS.max_pids * 16),
    ("the grader's own uid", False, False, None),
]


@pytest.mark.parametrize(
    ("dropped_uid", "own_namespace", "nproc"), [case[1:] for case in NPROC], ids=[case[0] for case in NPROC]
)
def test_process_count_rlimit_is_set_only_where_it_counts_the_childs_processes(
    dropped_uid: bool, own_namespace: bool, nproc: int | None
) -> None:
    table = {
        name: (soft, hard)
        for name, soft, hard in rlimit_table(
            LIMITS, dropped_uid=dropped_uid, own_user_namespace=own_namespace
        )
    }
    assert table.get("RLIMIT_NPROC") == (None if nproc is None else (nproc, nproc))
    assert table["RLIMIT_AS"] == (LIMITS.memory_bytes, LIMITS.memory_bytes)
    assert table["RLIMIT_CORE"] == (0, 0)


@pytest.mark.skipif(not FULL.is_active("cgroup"), reason="the cgroup tree is not writable here")
def test_unlocked_job_cgroups_are_removed_when_a_job_starts_and_locked_or_old_ones_kept() -> None:
    dead_pid = subprocess.Popen(["true"])
    dead_pid.wait()
    job = create_job_cgroup(memory_bytes=1536 << 20, max_pids=8)
    parents = [group.path.parent for group in job.groups]
    job.remove()
    stale = [parent / f"{JOB_PREFIX}{dead_pid.pid}-5ca1e" for parent in parents]
    # A live grader's job whose pid this namespace does not show: only its lock says it lives.
    held = [parent / f"{JOB_PREFIX}{dead_pid.pid}-11fe" for parent in parents]
    # An earlier version's job (no lock): nothing proves it abandoned.
    old = [parent / f"gymgrade-{dead_pid.pid}-01d" for parent in parents]
    for path in (*stale, *held, *old):
        path.mkdir()
    claims = [ownership.claim_new(path) for path in held]
    try:
        create_job_cgroup(memory_bytes=1536 << 20, max_pids=8).remove()
        assert [path for path in stale if path.exists()] == []
        assert [path for path in (*held, *old) if not path.exists()] == []
    finally:
        for claim in claims:
            claim.release()
        for path in (*held, *old):
            path.rmdir()


def test_the_harness_tree_holds_only_the_harness_and_the_compat_layer() -> None:
    tree = harness_tree()
    files = {path.relative_to(tree).as_posix() for path in tree.rglob("*") if path.is_file()}
    assert {
        "bootstrap.py",
        "landlock_syscalls.py",
        "lib/grader/__init__.py",
        "lib/grader/sandbox/__init__.py",
    } <= files
    assert (tree / "lib" / "grader" / "__init__.py").read_text() == ""
    tops = {name.split("/")[2] for name in files if name.startswith("lib/grader/") and name.count("/") > 2}
    assert tops == {"sandbox", "compat"}
    assert {
        name.split("/")[3] for name in files if name.startswith("lib/grader/sandbox/") and name.count("/") > 3
    } == {"child"}
    assert not any("reference" in name or name.endswith(".toml") for name in files)


def test_the_harness_tree_carries_bytecode_the_child_interpreter_accepts() -> None:
    # The child runs with -B in a read-only tree: what it does not find compiled it compiles at every start.
    lib = harness_tree() / "lib" / "grader"
    sources = sorted([*(lib / "sandbox" / "child").rglob("*.py"), *(lib / "compat").rglob("*.py")])
    assert sources
    for source in sources:
        header = Path(importlib.util.cache_from_source(str(source))).read_bytes()[:16]
        stat = source.stat()
        # What Python checks before it uses a cached file: magic, flags 0 (time stamp), mtime, size.
        assert header[:4] == importlib.util.MAGIC_NUMBER, source
        assert int.from_bytes(header[4:8], "little") == 0, source
        assert int.from_bytes(header[8:12], "little") == int(stat.st_mtime) & 0xFFFFFFFF, source
        assert int.from_bytes(header[12:16], "little") == stat.st_size & 0xFFFFFFFF, source


def test_import_hooks_of_the_site_directories_are_hidden_from_the_child() -> None:
    paths = python_paths()
    hooks = [
        entry
        for site_dir in paths.site_dirs
        for entry in Path(site_dir).iterdir()
        if entry.name.endswith(".pth") or entry.name.startswith("__editable__")
    ]
    assert set(hooks) <= set(paths.hidden)


def test_harness_trees_of_dead_graders_are_removed_and_live_ones_kept() -> None:
    dead = subprocess.Popen(["true"])
    dead.wait()
    stale = Path(tempfile.gettempdir()) / f"{TREE_PREFIX}{dead.pid}-stale"
    (stale / "lib").mkdir(parents=True)
    held = Path(tempfile.gettempdir()) / f"{TREE_PREFIX}{dead.pid}-held"
    held.mkdir()
    claim = ownership.claim_new(held) if ownership.LOCKS else None
    try:
        remove_stale_trees()
        assert not stale.exists()
        assert harness_tree().exists()
        # Where locks exist, a live grader's tree is kept whatever its name says (another PID namespace).
        assert held.exists() is ownership.LOCKS
    finally:
        if claim is not None:
            claim.release()
        if held.exists():
            held.rmdir()
