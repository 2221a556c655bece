"""The parent signals only what it can show is a child's: no hidden pid, not itself, no reused pid."""

from __future__ import annotations

import os
import signal
import subprocess
from collections.abc import Iterator

import pytest

from grader.sandbox import process_model, signalling

pytestmark = pytest.mark.skipif(process_model.MODEL != "posix", reason="signals are POSIX")


@pytest.fixture
def recorded(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[tuple[str, int]]]:
    """Records every signal the module would send, and sends none."""
    sent: list[tuple[str, int]] = []
    monkeypatch.setattr(signalling.os, "kill", lambda pid, _sig: sent.append(("kill", pid)))
    monkeypatch.setattr(signalling.os, "killpg", lambda pgid, _sig: sent.append(("killpg", pgid)))
    monkeypatch.setattr(signalling.signal, "pidfd_send_signal", lambda fd, _sig: sent.append(("pidfd", fd)))
    yield sent


@pytest.fixture
def sleeper() -> Iterator[subprocess.Popen[bytes]]:
    process = subprocess.Popen(["sleep", "60"], start_new_session=True)
    yield process
    process.kill()
    process.wait()


REFUSED = [
    ("zero: outside this PID namespace, or the caller's own group", lambda: 0),
    ("negative: a process group", lambda: -os.getpgrp()),
    ("init", lambda: 1),
    ("the grader itself", os.getpid),
    ("the grader's process group", os.getpgrp),
    ("the grader's session", lambda: os.getsid(0)),
]


@pytest.mark.parametrize("pid", [case[1] for case in REFUSED], ids=[case[0] for case in REFUSED])
def test_hidden_pids_and_the_graders_own_ids_are_refused(pid: object) -> None:
    assert callable(pid)
    assert signalling.refusal(pid()) is not None


def test_a_childs_pid_may_be_signalled(sleeper: subprocess.Popen[bytes]) -> None:
    assert signalling.refusal(sleeper.pid) is None


def test_refused_ids_are_never_signalled_even_when_listed_again(recorded: list[tuple[str, int]]) -> None:
    listed = {0, -1, 1, os.getpid(), os.getpgrp(), os.getsid(0)}
    assert signalling.kill_members(listed, lambda: listed) == 0
    assert signalling.kill_group(0) is False
    assert signalling.kill_group(os.getpgrp()) is False
    assert recorded == []


@pytest.mark.parametrize("pidfds", [True, False], ids=["pidfd", "without pidfds"])
def test_a_member_still_listed_is_killed(
    sleeper: subprocess.Popen[bytes], pidfds: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    if not pidfds:
        monkeypatch.delattr(os, "pidfd_open", raising=False)
    assert signalling.kill_members([sleeper.pid], lambda: {sleeper.pid}) == 1
    assert sleeper.wait(timeout=10) == -signal.SIGKILL


@pytest.mark.parametrize("pidfds", [True, False], ids=["pidfd", "without pidfds"])
def test_a_pid_no_longer_listed_when_checked_again_is_not_signalled(
    sleeper: subprocess.Popen[bytes], pidfds: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Between the listing and the signal the member was reaped and its pid reused by another process."""
    if not pidfds:
        monkeypatch.delattr(os, "pidfd_open", raising=False)
    assert signalling.kill_members([sleeper.pid], set) == 0
    assert sleeper.poll() is None


def test_a_childs_own_group_is_killed(sleeper: subprocess.Popen[bytes]) -> None:
    assert signalling.kill_group(sleeper.pid) is True
    assert sleeper.wait(timeout=10) == -signal.SIGKILL


def test_ending_a_reaped_child_signals_nothing(recorded: list[tuple[str, int]]) -> None:
    done = subprocess.Popen(["true"], start_new_session=True)
    done.wait()
    process_model.end(done)
    assert recorded == []
