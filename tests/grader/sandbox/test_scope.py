"""A grading leaves no harness tree, scratch dir, cgroup or process behind, even when its run is killed."""

from __future__ import annotations

import os
import secrets
import tempfile
import textwrap
import time
from pathlib import Path

import pytest

from grader.grading.grade import grade_files
from grader.grading.outcomes import OnResult
from grader.grading.plan import GradingPlan
from grader.report import Report
from grader.sandbox import IsolationPolicy, probe_isolation
from grader.sandbox.isolation.cgroup import CGROUP_RECORDS
from grader.sandbox.isolation.scope import SCOPE_PREFIX, sandbox_scope

SUBMISSION = textwrap.dedent("""
    import gymnasium


    def random_blackjack(n):
        env = gymnasium.make("Blackjack-v1", natural=False, sab=False)
        wins = 0
        for _ in range(n):
            env.reset()
            done = False
            while not done:
                _, reward, terminated, truncated, _ = env.step(env.action_space.sample())
                done = terminated or truncated
            wins += reward > 0
        return wins / n


    def cartpole():
        with open("/proc/self/comm", "w") as comm:  # the event the test waits for: cartpole() has begun
            comm.write("MARKER")
        while True:
            pass
""")
MARKER_PREFIX = "cp-"
"""cartpole() names its process ``cp-<token>`` (a process name holds 15 characters)."""

HANG_SECONDS = 120.0

pytestmark = [
    pytest.mark.sandbox,
    pytest.mark.skipif(
        not probe_isolation().full, reason="needs full isolation:\n" + probe_isolation().summary()
    ),
]


@pytest.fixture
def private_tmp(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A temp dir of this test's own, for the grading and the pytest run it starts."""
    directory = tmp_path / "tmp"
    directory.mkdir()
    monkeypatch.setenv("TMPDIR", str(directory))
    monkeypatch.setattr(tempfile, "tempdir", None)
    return directory


def _recorded_cgroups(tmp: Path) -> set[Path]:
    """The job cgroups the grading's scope knows of right now."""
    paths = set()
    for record in tmp.glob(f"{SCOPE_PREFIX}*/{CGROUP_RECORDS}/*"):
        paths.update(Path(line.split(" ", 1)[1]) for line in record.read_text().splitlines() if line)
    return paths


def _named(name: str) -> list[int]:
    """The live processes whose name (``/proc/PID/comm``) is ``name``."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                if (entry / "comm").read_text().strip() == name:
                    found.append(int(entry.name))
            except OSError:
                continue
    return found


def _processes_mentioning(token: str) -> list[str]:
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit() and int(entry.name) != os.getpid():
            try:
                command = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
                state = (entry / "stat").read_text().rsplit(")", 1)[1].split()[0]
            except (OSError, IndexError):
                continue
            if token in command and state != "Z":
                found.append(f"{entry.name}: {command[:200]}")
    return found


@pytest.mark.parametrize("abandoned", [False, True], ids=["completed", "killed-mid-run"])
def test_a_grading_leaves_nothing_behind(private_tmp: Path, tmp_path: Path, abandoned: bool) -> None:
    token = secrets.token_hex(6)
    submission = tmp_path / f"student_{token}.py"
    marker = MARKER_PREFIX + token
    submission.write_text(SUBMISSION.replace("MARKER", marker))
    plan = GradingPlan.load(None, ["random_blackjack", "cartpole"] if abandoned else ["random_blackjack"])
    seen: set[Path] = set()

    def on_result(path: Path, result: object) -> None:
        if abandoned:  # random_blackjack()'s result: kill the run once cartpole() is under way, not before
            deadline = time.monotonic() + HANG_SECONDS  # bounds a hang only: the loop ends at the event
            while not _named(marker):
                assert time.monotonic() < deadline, f"cartpole() did not begin within {HANG_SECONDS} s"
                time.sleep(0.05)
        seen.update(_recorded_cgroups(private_tmp))
        if abandoned:
            raise KeyboardInterrupt

    def grade() -> list[Report]:
        return grade_files(
            [submission],
            plan,
            seed=5,
            workers=2,
            policy=IsolationPolicy.ALLOW_FALLBACK,
            listener=OnResult(on_result),
        )

    if abandoned:
        with pytest.raises(KeyboardInterrupt):
            grade()
        assert seen, "cartpole()'s sandbox was running when the run was killed"
    else:
        [report] = grade()
        assert [problem.status for problem in report.problems] == ["passed"], report.problems[0].feedback

    assert sorted(path.name for path in private_tmp.glob("gymgrade-*")) == []  # pytest's own dirs may stay
    assert [path for path in seen if path.exists()] == []
    deadline = time.monotonic() + HANG_SECONDS  # SIGKILLed processes take a moment to go; bounds a hang only
    while (_processes_mentioning(token) or _named(marker)) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert _processes_mentioning(token) == []
    assert _named(marker) == [], "cartpole()'s process outlived the run"


def test_closing_a_scope_removes_its_cgroups_and_files(private_tmp: Path) -> None:
    from grader.sandbox.isolation.cgroup import create_job_cgroup

    with sandbox_scope() as variables:
        os.environ.update(variables)
        try:
            job = create_job_cgroup(memory_bytes=1 << 30, max_pids=16)
            (Path(variables["GYMGRADE_SANDBOX_SCOPE"]) / "gymgrade-tree-1-x").mkdir()
        finally:
            for name in variables:
                del os.environ[name]
        paths = [group.path for group in job.groups]
        assert all(path.exists() for path in paths)

    assert [path for path in paths if path.exists()] == []
    assert list(private_tmp.iterdir()) == []
