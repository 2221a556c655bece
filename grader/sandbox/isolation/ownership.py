"""Who owns a job's cgroup or a harness tree, proven the same way in every PID namespace: a lock it holds.

A pid in a directory's name means nothing across PID namespaces: a grader in a container sees a host
grader's pid as missing, and took its live jobs for stale (issue 46). So the process that makes a job
cgroup or a harness tree locks the directory (`flock`, exclusive) at once and holds the lock for as long
as the directory is its own; the kernel drops the lock when that process ends, however it ends. The
lock is on the directory itself, so every grader that sees the directory (the same cgroup hierarchy, the
same temp directory), in whatever PID namespace, asks the same question and gets the same answer.

- `claim_new(path)`: the creator's lock, taken right after `mkdir`; OSError when a sweep took the new,
  empty directory first (the creator makes another).
- `claim_abandoned(path)`: a sweep's lock on a directory nobody holds, kept while the sweep removes it;
  None when its owner lives (or the directory is gone or unreadable). A sweep never removes what it could
  not claim, so two sweeps never remove the same directory and no live job is taken for stale.

Needs `Feature.FILE_LOCKS` (POSIX); without it (Windows, which has no PID namespaces) the harness trees'
sweep asks whether the pid in the name runs.
"""

from __future__ import annotations

import contextlib
import errno
import os
from pathlib import Path
from types import TracebackType

from grader.sandbox.host import HOST, Feature

LOCKS = HOST.has(Feature.FILE_LOCKS)
"""Whether ownership is proven by locks here."""


class Claim:
    """An exclusive lock held on a directory until `release` (or until this process ends)."""

    def __init__(self, path: Path, descriptor: int) -> None:
        self.path = path
        self._descriptor: int | None = descriptor

    def release(self) -> None:
        """Drops the lock (idempotent)."""
        if self._descriptor is not None:
            with contextlib.suppress(OSError):
                os.close(self._descriptor)
            self._descriptor = None

    def __enter__(self) -> Claim:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None
    ) -> None:
        self.release()


def _lock(path: Path) -> Claim | None:
    """The lock of `path` if nobody holds it; None when someone does.

    Raises:
        OSError: the directory cannot be opened (gone, unreadable).
    """
    import fcntl

    descriptor = os.open(path, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    try:
        fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(descriptor)
        return None
    except BaseException:
        os.close(descriptor)
        raise
    try:
        same = os.stat(path).st_ino == os.fstat(descriptor).st_ino
    except FileNotFoundError:
        same = False
    if not same:  # removed (and perhaps made again) between the open and the lock
        os.close(descriptor)
        raise FileNotFoundError(errno.ENOENT, "the directory was removed while being locked", str(path))
    return Claim(path, descriptor)


def claim_new(path: Path) -> Claim:
    """Locks the directory this process has just made.

    Raises:
        OSError: a sweep took or removed the directory first (make another), or locks are not available.
    """
    if not LOCKS:
        raise OSError(errno.ENOSYS, f"this system ({HOST.system}) has no {Feature.FILE_LOCKS.value}")
    claim = _lock(path)
    if claim is None:
        raise BlockingIOError(errno.EWOULDBLOCK, "a sweep holds the directory just made", str(path))
    return claim


def claim_abandoned(path: Path) -> Claim | None:
    """The lock of a directory whose owner has ended, for a sweep to remove it under; None otherwise."""
    if not LOCKS:
        return None
    try:
        return _lock(path)
    except OSError:
        return None
