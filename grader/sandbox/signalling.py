"""Signalling the sandbox's processes: only what the grader can show is a child's, never the grader itself.

The parent SIGKILLs the processes of a child's job (a cgroup lists them) and a child's process group. What
a list names is not always a process the grader may end: inside a PID namespace, `cgroup.procs` lists a
process outside the namespace as 0 (and `kill(0, ...)` is the caller's own process group); a pid read a
moment ago may belong to another process once its own was reaped; and a group id equal to the grader's
own group would end the grader. So every signal the parent sends goes through this module:

- `refusal(pid)`: why a pid or group id is never signalled: 0 or below (a namespace hides the process, or
  the number names a group), 1 (a namespace's init), the grader's own pid, process group or session.
- `kill_members(pids, members)`: SIGKILLs each listed pid that is still a member when checked again
  after the process was pinned with a pidfd (`os.pidfd_open`, `signal.pidfd_send_signal`), so a pid
  reused by another process between the listing and the signal is never hit; without pidfds (a kernel
  before 5.3, a Python without them) the same checks run before a plain `os.kill`.
- `kill_group(pgid)`: SIGKILLs a child's process group (the child leads its own session).

POSIX only; `grader.sandbox.process_model` and the cgroup layer call it only where the host has POSIX
processes.
"""

from __future__ import annotations

import contextlib
import errno
import os
import signal
from collections.abc import Callable, Iterable

_PIDFD_UNAVAILABLE = (errno.ENOSYS, errno.EINVAL, errno.EPERM)
"""`pidfd_open` fails so on a kernel without it (ENOSYS) or where a sandbox (seccomp) refuses it."""


def protected_ids() -> frozenset[int]:
    """Pids and group ids the grader never signals: init, its own process, process group and session."""
    ids = {1, os.getpid()}
    with contextlib.suppress(OSError):
        ids.add(os.getpgrp())
    with contextlib.suppress(OSError):
        ids.add(os.getsid(0))
    return frozenset(ids)


def refusal(pid: int) -> str | None:
    """Why `pid` (a process or group id read from a list) must not be signalled; None when it may be."""
    if pid <= 0:
        return f"{pid} is not a process this grader can see (a PID namespace shows a process outside it as 0)"
    if pid in protected_ids():
        return f"{pid} is the grader's own process, process group or session, or init"
    return None


def _open_pidfd(pid: int) -> int | None:
    """A pidfd pinning process `pid`; None where pidfds are not available.

    Raises:
        ProcessLookupError: the process is gone.
    """
    opener = getattr(os, "pidfd_open", None)
    if opener is None or not hasattr(signal, "pidfd_send_signal"):
        return None
    try:
        descriptor: int = opener(pid)
    except ProcessLookupError:
        raise
    except OSError as error:
        if error.errno in _PIDFD_UNAVAILABLE:
            return None
        raise
    return descriptor


def kill_members(pids: Iterable[int], members: Callable[[], set[int]]) -> int:
    """SIGKILLs each of `pids` that `members()`, read after the processes were pinned, still lists.

    Args:
        pids: Process ids as a list of the job's members showed them (0 and other refused ids are skipped).
        members: Reads the job's members again (visible pids only).

    Returns:
        How many processes were signalled.
    """
    pinned: dict[int, int | None] = {}
    try:
        for pid in pids:
            if refusal(pid) is not None:
                continue
            with contextlib.suppress(ProcessLookupError, PermissionError):
                pinned[pid] = _open_pidfd(pid)
        if not pinned:
            return 0
        still = members()
        signalled = 0
        for pid, descriptor in pinned.items():
            if pid not in still:
                continue
            with contextlib.suppress(ProcessLookupError, PermissionError):
                if descriptor is None:
                    os.kill(pid, signal.SIGKILL)
                else:
                    signal.pidfd_send_signal(descriptor, signal.SIGKILL)
                signalled += 1
        return signalled
    finally:
        for descriptor in pinned.values():
            if descriptor is not None:
                os.close(descriptor)


def kill_group(pgid: int) -> bool:
    """SIGKILLs the process group `pgid` unless `refusal` forbids it; False when nothing was signalled."""
    if refusal(pgid) is not None:
        return False
    try:
        os.killpg(pgid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        return False
    return True
