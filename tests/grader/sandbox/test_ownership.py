"""A directory belongs to the process holding its lock, in every PID namespace; a sweep takes only what
nobody holds."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from grader.sandbox.isolation import ownership

pytestmark = pytest.mark.skipif(not ownership.LOCKS, reason="file locks are POSIX")
HOLD = "import os, sys, fcntl; d = os.open(sys.argv[1], os.O_RDONLY); fcntl.flock(d, fcntl.LOCK_EX); print('held', flush=True); sys.stdin.read()"  # noqa: E501
"""An owner: locks the directory, says so, and ends when its stdin closes (unshare --fork waits for it)."""


def test_a_claimed_directory_cannot_be_claimed_by_a_sweep_until_released(tmp_path: Path) -> None:
    claim = ownership.claim_new(tmp_path)
    assert ownership.claim_abandoned(tmp_path) is None
    claim.release()
    swept = ownership.claim_abandoned(tmp_path)
    assert swept is not None
    with pytest.raises(BlockingIOError):
        ownership.claim_new(tmp_path)
    swept.release()


def test_a_directory_removed_before_it_was_locked_is_not_claimed(tmp_path: Path) -> None:
    gone = tmp_path / "gone"
    with pytest.raises(FileNotFoundError):
        ownership.claim_new(gone)
    assert ownership.claim_abandoned(gone) is None


OWNERS = [
    ("same PID namespace", ()),
    ("another PID namespace", ("unshare", "--pid", "--fork", "--mount-proc")),
]


@pytest.mark.slow
@pytest.mark.parametrize("namespace", [case[1] for case in OWNERS], ids=[case[0] for case in OWNERS])
def test_the_owners_lock_holds_across_pid_namespaces_and_ends_with_it(
    tmp_path: Path, namespace: tuple[str, ...]
) -> None:
    if namespace and (shutil.which("unshare") is None or not Path("/proc/self/ns/pid").exists()):
        pytest.skip("unshare is not available")
    owner = subprocess.Popen(
        [*namespace, sys.executable, "-c", HOLD, str(tmp_path)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    assert owner.stdin is not None
    assert owner.stdout is not None
    try:
        assert owner.stdout.readline().strip() == "held"
        assert ownership.claim_abandoned(tmp_path) is None
    finally:
        owner.stdin.close()
        owner.wait(timeout=60)
    swept = ownership.claim_abandoned(tmp_path)
    assert swept is not None
    swept.release()
