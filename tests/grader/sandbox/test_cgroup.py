"""A job cgroup's kill, on fake cgroup directories: what a PID namespace hides is never signalled."""

from __future__ import annotations

import os
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

from grader.sandbox import process_model, signalling
from grader.sandbox.isolation.cgroup import JobCgroup, Members, _Group

pytestmark = pytest.mark.skipif(process_model.MODEL != "posix", reason="cgroups and signals are POSIX")


@pytest.fixture
def recorded(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[int]]:
    """Records every process the job's kill signals, and signals none."""
    sent: list[int] = []
    monkeypatch.setattr(signalling.os, "kill", lambda pid, _sig: sent.append(pid))
    monkeypatch.setattr(signalling.signal, "pidfd_send_signal", lambda fd, _sig: sent.append(fd))
    monkeypatch.setattr(signalling.os, "killpg", lambda pgid, _sig: sent.append(pgid))
    yield sent


def fake_group(directory: Path, version: int, procs: str, *, kill_file: bool = False) -> _Group:
    directory.mkdir()
    (directory / "cgroup.procs").write_text(procs)
    if kill_file:
        (directory / "cgroup.kill").write_text("")
    return _Group(directory, version, ())


def test_members_count_what_a_pid_namespace_shows_as_zero(tmp_path: Path) -> None:
    job = JobCgroup(
        [fake_group(tmp_path / "v2", 2, "0\n0\n4242\n"), fake_group(tmp_path / "v1", 1, "0\n4242\n")]
    )
    assert job.members() == Members(frozenset({4242}), hidden=2)
    assert job.pids() == {4242}
    assert not job.members().empty


@pytest.mark.parametrize("version", [1, 2], ids=["v1", "v2 without cgroup.kill"])
def test_a_job_of_hidden_processes_is_left_alone_at_once(
    tmp_path: Path, version: int, recorded: list[int]
) -> None:
    """Without `cgroup.kill` nothing can reach a process this namespace does not show: no signal by number."""
    job = JobCgroup([fake_group(tmp_path / "job", version, "0\n0\n")])
    assert job.kill(timeout=60) is False
    assert recorded == []


def test_the_graders_own_ids_listed_in_a_job_are_never_signalled(tmp_path: Path, recorded: list[int]) -> None:
    own = {1, os.getpid(), os.getpgrp(), os.getsid(0)}
    job = JobCgroup([fake_group(tmp_path / "job", 1, "".join(f"{pid}\n" for pid in own))])
    assert job.kill(timeout=60) is False
    assert recorded == []


def test_the_kernel_kills_the_job_where_a_v2_group_has_cgroup_kill(
    tmp_path: Path, recorded: list[int]
) -> None:
    group = fake_group(tmp_path / "job", 2, "0\n", kill_file=True)
    assert JobCgroup([group]).kill(timeout=0.05) is False  # the fake's list never empties
    assert (group.path / "cgroup.kill").read_text() == "1"
    assert recorded == []


def test_a_visible_member_is_killed_and_the_job_empties(tmp_path: Path) -> None:
    sleeper = subprocess.Popen(["sleep", "60"], start_new_session=True)
    procs = tmp_path / "job" / "cgroup.procs"
    group = fake_group(tmp_path / "job", 1, f"0\n{sleeper.pid}\n")
    try:
        job = JobCgroup([group])
        # The fake list stays as written while the process lives; once killed, the test empties it.
        killed = signalling.kill_members(job.members().visible, job.pids)
        assert killed == 1
        assert sleeper.wait(timeout=10) < 0
        procs.write_text("")
        assert job.kill(timeout=60) is True
    finally:
        sleeper.kill()
        sleeper.wait()
