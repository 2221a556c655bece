"""The isolation layer plug-ins: each layer's probe and apply, the one list, and a new layer added to it."""

from __future__ import annotations

import json
import os
import textwrap
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from marker_layer import MARKER_VARIABLE, MarkerLayer

from grader.sandbox import Call, IsolationPolicy, Limits, OutcomeStatus, Sandbox, probe_isolation
from grader.sandbox.isolation import bubblewrap, cgroup, landlock, privileges, registry, rlimits, seccomp
from grader.sandbox.isolation.cgroup import JOIN_FAILED_EXIT, JobCgroup, join_argv
from grader.sandbox.isolation.filesystem import SYSTEM_DIRS, ChildView, harness_tree, python_paths
from grader.sandbox.isolation.launch import build_launch
from grader.sandbox.isolation.layer import IsolationReport, LaunchSpec, LayerReport

LAYER_ORDER = ["cgroup", "bubblewrap", "seccomp", "privileges", "rlimits", "landlock"]
LIMITS = Limits(call_seconds=5, import_seconds=20)
FULL = probe_isolation()
MakeSpec = Callable[[set[str]], LaunchSpec]


def _report(active: set[str], names: list[str] = LAYER_ORDER) -> IsolationReport:
    return IsolationReport(tuple(LayerReport(name, name in active, "probed by the test") for name in names))


@pytest.fixture
def make_spec() -> Iterator[MakeSpec]:
    """Builds specs as build_launch does and releases whatever their layers created afterwards."""
    made: list[LaunchSpec] = []

    def make(active: set[str]) -> LaunchSpec:
        spec = LaunchSpec(_report(active), LIMITS, python_paths(), harness_tree(), b"x = 1\n", "s.py")
        made.append(spec)
        return spec

    yield make
    for spec in made:
        spec.launch.cleanup()


def _bootstrap_config(argv: list[str]) -> dict[str, object]:
    config = json.loads(argv[-1])
    assert isinstance(config, dict)
    return config


def test_the_list_declares_every_layer_once_outermost_first() -> None:
    assert [layer.name for layer in registry.LAYERS] == LAYER_ORDER
    assert [layer.name for layer in FULL.layers] == LAYER_ORDER


LANDLOCK_PROBES = [
    ("under bubblewrap", True, False, "not needed: bubblewrap already hides the file system"),
    ("without bubblewrap", False, landlock.landlock_syscalls.abi_version() >= 1, "fallback (ABI"),
]


@pytest.mark.parametrize(
    ("bubblewrap_active", "active", "detail"),
    [case[1:] for case in LANDLOCK_PROBES],
    ids=[case[0] for case in LANDLOCK_PROBES],
)
def test_landlock_is_probed_from_the_bubblewrap_report_outside_it(
    bubblewrap_active: bool, active: bool, detail: str
) -> None:
    report = landlock.LandlockLayer().probe(_report({"bubblewrap"} if bubblewrap_active else set()))
    assert report.active is active
    assert not report.required
    if active or bubblewrap_active:
        assert report.detail.startswith(detail)


PRIVILEGE_PROBES = [
    ("root under bubblewrap", True, True, False, True),
    ("root, no bubblewrap, interpreter readable", True, False, True, True),
    ("root, no bubblewrap, interpreter unreadable", True, False, False, False),
    ("not root, no bubblewrap, interpreter unreadable", False, False, False, True),
]


@pytest.mark.parametrize(
    ("root", "bubblewrap_active", "readable", "active"),
    [case[1:] for case in PRIVILEGE_PROBES],
    ids=[case[0] for case in PRIVILEGE_PROBES],
)
def test_privileges_are_missing_only_where_a_dropped_uid_could_not_reach_the_interpreter(
    monkeypatch: pytest.MonkeyPatch, root: bool, bubblewrap_active: bool, readable: bool, active: bool
) -> None:
    machine = LayerReport("privileges", True, "drops to uid 65534")
    monkeypatch.setattr(privileges, "_probe_machine", lambda: machine)
    monkeypatch.setattr(privileges, "running_as_root", lambda: root)
    monkeypatch.setattr(privileges, "_interpreter_readable_by_others", lambda: readable)
    report = privileges.PrivilegesLayer().probe(_report({"bubblewrap"} if bubblewrap_active else set()))
    assert report.active is active
    if not active:
        assert report.detail.startswith("running as root without bubblewrap")
        assert report.remedy == "install bubblewrap, or install Python where every user can read it"


def test_switching_a_layer_off_is_what_the_layers_inside_it_see(monkeypatch: pytest.MonkeyPatch) -> None:
    marker = MarkerLayer()
    monkeypatch.setattr(registry, "LAYERS", (bubblewrap.BubblewrapLayer(), marker, landlock.LandlockLayer()))
    report = probe_isolation(frozenset({"bubblewrap"}))
    assert [layer.name for layer in report.layers] == ["bubblewrap", "marker", "landlock"]
    assert not report.is_active("bubblewrap")
    assert report.layer("landlock").detail != "not needed: bubblewrap already hides the file system"
    assert marker.outer_seen == [("bubblewrap",)]


ROOT_CASES = [("as root", True), ("as a user", False)]


@pytest.mark.parametrize("root", [case[1] for case in ROOT_CASES], ids=[case[0] for case in ROOT_CASES])
def test_privileges_wrap_the_interpreter_in_setpriv_only_as_root(
    monkeypatch: pytest.MonkeyPatch, make_spec: MakeSpec, root: bool
) -> None:
    monkeypatch.setattr(privileges, "running_as_root", lambda: root)
    spec = make_spec({"privileges"})
    privileges.PrivilegesLayer().apply(spec)
    assert [wrapper(spec) for wrapper in spec.wrappers] == ([privileges.drop_argv()] if root else [])


NPROC_CASES = [
    ("root, privileges, bubblewrap", True, {"privileges", "bubblewrap"}, LIMITS.max_pids * 16),
    ("user, bubblewrap", False, {"privileges", "bubblewrap"}, LIMITS.max_pids),
    ("user, no bubblewrap", False, {"privileges"}, None),
    ("root, privileges off", True, {"bubblewrap"}, None),
]


@pytest.mark.parametrize(
    ("root", "active", "nproc"), [case[1:] for case in NPROC_CASES], ids=[case[0] for case in NPROC_CASES]
)
def test_rlimits_derive_the_process_limit_from_the_layers_outside(
    monkeypatch: pytest.MonkeyPatch,
    make_spec: MakeSpec,
    root: bool,
    active: set[str],
    nproc: int | None,
) -> None:
    monkeypatch.setattr(rlimits, "running_as_root", lambda: root)
    spec = make_spec({*active, "rlimits"})
    rlimits.RlimitsLayer().apply(spec)
    table = {name: (soft, hard) for name, soft, hard in spec.bootstrap.rlimits}
    assert table.get("RLIMIT_NPROC") == (None if nproc is None else (nproc, nproc))
    assert table["RLIMIT_CPU"] == (LIMITS.cpu_seconds, LIMITS.cpu_seconds + rlimits.CPU_GRACE_SECONDS)
    assert spec.wrappers == []


def test_landlock_without_bubblewrap_limits_the_child_to_a_host_scratch(make_spec: MakeSpec) -> None:
    spec = make_spec({"landlock"})
    landlock.LandlockLayer().apply(spec)
    rules = spec.bootstrap.landlock
    assert rules is not None and spec.launch.scratch is not None
    assert rules["write"] == [str(spec.launch.scratch)]
    assert str(harness_tree()) in rules["read"] and set(SYSTEM_DIRS) <= set(rules["read"])
    assert (spec.launch.scratch / ".submission" / "s.py").read_bytes() == b"x = 1\n"


def test_bubblewrap_wraps_the_final_environment_and_takes_over_the_syscall_filter(
    make_spec: MakeSpec,
) -> None:
    spec = make_spec({"bubblewrap"})
    bubblewrap.BubblewrapLayer().apply(spec)
    spec.bootstrap.seccomp_fd = 1234  # as a syscall filter layer inside it would
    spec.environment[MARKER_VARIABLE] = "late"  # as a layer inside it would, after bwrap applied
    launch = spec.compose(["--submission", spec.child_view().submission])
    argv = launch.argv
    assert argv[0].endswith("bwrap") and launch.signals_in_exit_status
    assert launch.env == {} and launch.cwd is None and launch.scratch is None
    dash = argv.index("--")
    assert argv[dash - 2 : dash] == ["--seccomp", "1234"]
    marked = argv.index(MARKER_VARIABLE)
    assert argv[marked - 1 : marked + 2] == ["--setenv", MARKER_VARIABLE, "late"]
    assert argv[argv.index("HOME") - 1 : argv.index("HOME") + 2] == ["--setenv", "HOME", "/tmp"]
    config = _bootstrap_config(argv)
    assert config["seccomp_fd"] is None
    assert config["harness_argv"] == ["--submission", "/submission/s.py"]
    assert argv[dash + 1 : dash + 4] == [str(python_paths().executable), "-S", "-B"]
    assert argv[dash + 4] == "/gymgrade/bootstrap.py"


def test_a_second_file_system_view_is_refused(make_spec: MakeSpec) -> None:
    spec = make_spec(set())
    spec.provide_view(bubblewrap.private_view("s.py"))
    with pytest.raises(RuntimeError, match="only one layer may give the child its file system"):
        spec.provide_view(ChildView("/elsewhere", "/h", "/s"))


@pytest.mark.skipif(not FULL.is_active("seccomp"), reason="no seccomp bindings here")
def test_seccomp_hands_the_bootstrap_a_compiled_filter(make_spec: MakeSpec) -> None:
    spec = make_spec({"seccomp"})
    seccomp.SeccompLayer().apply(spec)
    descriptor = spec.bootstrap.seccomp_fd
    assert descriptor is not None and spec.launch.pass_fds == [descriptor]
    assert os.fstat(descriptor).st_size % 8 == 0 and os.fstat(descriptor).st_size > 0
    assert _bootstrap_config(spec.compose([]).argv)["seccomp_fd"] == descriptor


def test_the_cgroup_join_wrapper_writes_its_pid_into_every_group() -> None:
    job = JobCgroup([cgroup._Group(Path("/sys/fs/cgroup/gymgrade-1-ab"), 2, ("memory",))])
    argv = join_argv(job)
    assert argv[:2] == ["/bin/sh", "-c"] and f"exit {JOIN_FAILED_EXIT}" in argv[2]
    assert argv[3:] == ["gymgrade-join", "/sys/fs/cgroup/gymgrade-1-ab/cgroup.procs", "--"]


@pytest.mark.skipif(not FULL.is_active("cgroup"), reason="the cgroup tree is not writable here")
def test_cgroup_places_the_child_in_a_job_joined_first(make_spec: MakeSpec) -> None:
    spec = make_spec({"cgroup"})
    cgroup.CgroupLayer().apply(spec)
    job = spec.launch.cgroup
    assert job is not None and job.limited == {"memory", "pids", "cpu"}
    argv = spec.compose([]).argv
    assert argv[: argv.index("--") + 1] == join_argv(job)


def test_with_no_layer_active_the_interpreter_runs_the_bootstrap_in_a_host_scratch() -> None:
    launch = build_launch(
        _report(set()),
        LIMITS,
        submission=b"x = 1\n",
        submission_name="s.py",
        requests_fd=5,
        results_fd=6,
        import_seed=7,
    )
    try:
        assert launch.scratch is not None and launch.cwd == str(launch.scratch)
        bootstrap = f"{harness_tree()}/bootstrap.py"
        assert launch.argv[:4] == [str(python_paths().executable), "-S", "-B", bootstrap]
        config = _bootstrap_config(launch.argv)
        assert (config["rlimits"], config["landlock"], config["seccomp_fd"]) == ([], None, None)
        assert launch.env["HOME"] == str(launch.scratch) and launch.pass_fds == []
    finally:
        launch.cleanup()
    assert not launch.scratch.exists()


MARKER_CHILD = textwrap.dedent("""
    import os


    def marker():
        return os.environ.get("GYMGRADE_MARKER")
""")


@pytest.fixture
def marker(monkeypatch: pytest.MonkeyPatch) -> MarkerLayer:
    """A new layer module's layer, added as the one line in the list (innermost)."""
    layer = MarkerLayer()
    monkeypatch.setattr(registry, "LAYERS", (*registry.LAYERS, layer))
    return layer


def test_a_new_layer_in_the_list_is_probed_after_the_others_and_reported(marker: MarkerLayer) -> None:
    report = probe_isolation()
    assert [layer.name for layer in report.layers] == [*LAYER_ORDER, "marker"]
    assert report.layer("marker") == LayerReport("marker", True, "marks the child's environment")
    assert marker.outer_seen == [tuple(LAYER_ORDER)]
    switched_off = probe_isolation(frozenset({"marker"})).layer("marker")
    assert switched_off.detail == "switched off by the caller (marks the child's environment)"
    marker.available = False
    assert [layer.name for layer in probe_isolation().missing] == [layer.name for layer in FULL.missing] + [
        "marker"
    ]


@pytest.mark.parametrize(("disable", "applied"), [((), 1), (("marker",), 0)], ids=["active", "switched off"])
def test_a_new_layer_in_the_list_is_applied_only_while_active(
    marker: MarkerLayer, disable: tuple[str, ...], applied: int
) -> None:
    launch = build_launch(
        probe_isolation(frozenset(disable)),
        LIMITS,
        submission=b"x = 1\n",
        submission_name="s.py",
        requests_fd=5,
        results_fd=6,
        import_seed=7,
    )
    launch.cleanup()
    assert marker.applied == applied
    assert (MARKER_VARIABLE in launch.argv or MARKER_VARIABLE in launch.env) == bool(applied)


@pytest.mark.sandbox
@pytest.mark.skipif(not FULL.full, reason="needs full isolation:\n" + FULL.summary())
def test_a_new_layer_reaches_a_real_child_under_every_other_layer(
    marker: MarkerLayer, tmp_path: Path
) -> None:
    submission = tmp_path / "marker.py"
    submission.write_text(MARKER_CHILD)
    with Sandbox(submission, seed=0, limits=LIMITS, policy=IsolationPolicy.REQUIRE_FULL) as sandbox:
        outcome = sandbox.call(Call("marker"))
    assert outcome.status is OutcomeStatus.OK, outcome.message + outcome.stderr
    assert outcome.value == "applied"
    assert sandbox.isolation.is_active("marker")
