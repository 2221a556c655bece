"""The time of a cloned repository's checked-out commit, read from its ``.git`` folder without running git.

GitHub Classroom's download is a folder of ``git clone``s; the submission's time is the committer time of
the commit checked out (``HEAD``). Git is not run on a student's repository (its configuration could name
programs to run); its files are read instead, each bounded, none through a symbolic link: ``HEAD``, the
branch's ref (loose or in ``packed-refs``), and the commit object, loose (zlib) or in a pack (found through
the pack's version 2 index). A commit stored as a delta, or anything unexpected, gives None: the time is then
unknown, never guessed.

The committer time is what the student's clock said when they committed; a student can set it. Where push
times matter, give them with ``--submitted-at``.
"""

from __future__ import annotations

import os
import re
import stat
import zlib
from datetime import datetime, timedelta, timezone
from pathlib import Path

GIT_FOLDER = ".git"
MAX_SMALL_FILE_BYTES = 1 * 2**20
"""Bytes read of HEAD, a ref or packed-refs."""
MAX_COMMIT_BYTES = 256 * 2**10
"""Bytes of a commit object inflated (a commit is a few hundred bytes; its message may be long)."""
MAX_INDEX_BYTES = 256 * 2**20
PACK_INDEX_MAGIC = b"\377tOc"
COMMIT_TYPE = 1
SHA = re.compile(rb"^[0-9a-f]{40}$")
REF = re.compile(rb"^ref: (refs/[A-Za-z0-9._/-]+)\s*$")
COMMITTER = re.compile(rb"^committer .* (\d{1,12}) ([+-])(\d{2})(\d{2})$", re.MULTILINE)


def _read(path: Path, limit: int, offset: int = 0) -> bytes | None:
    """At most ``limit`` bytes of a regular file (never through a link), None when there is none."""
    try:
        descriptor = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    except OSError:
        return None
    try:
        if not stat.S_ISREG(os.fstat(descriptor).st_mode):
            return None
        if offset:
            os.lseek(descriptor, offset, os.SEEK_SET)
        chunks, left = [], limit
        while left > 0:
            chunk = os.read(descriptor, min(left, 2**20))
            if not chunk:
                break
            chunks.append(chunk)
            left -= len(chunk)
        return b"".join(chunks)
    except OSError:
        return None
    finally:
        os.close(descriptor)


def _inside(git: Path) -> bool:
    """``git`` is a real folder (not a link, not a ``gitdir:`` file a submodule would leave)."""
    try:
        return stat.S_ISDIR(os.lstat(git).st_mode)
    except OSError:
        return False


def head_commit(repository: Path) -> bytes | None:
    """The hex id of the commit ``HEAD`` names in ``repository`` (its ``.git`` folder), None when unknown."""
    git = repository / GIT_FOLDER
    if not _inside(git):
        return None
    head = (_read(git / "HEAD", MAX_SMALL_FILE_BYTES) or b"").strip()
    if SHA.match(head):
        return head
    ref = REF.match(head)
    if ref is None or b".." in ref[1]:
        return None
    name = ref[1]
    loose = (_read(git / name.decode(), MAX_SMALL_FILE_BYTES) or b"").strip()
    if SHA.match(loose):
        return loose
    for line in (_read(git / "packed-refs", MAX_SMALL_FILE_BYTES) or b"").splitlines():
        parts = line.split(b" ")
        if len(parts) == 2 and parts[1] == name and SHA.match(parts[0]):
            return parts[0]
    return None


def _inflate(data: bytes) -> bytes | None:
    try:
        return zlib.decompressobj().decompress(data, MAX_COMMIT_BYTES)
    except zlib.error:
        return None


def _loose(git: Path, sha: str) -> bytes | None:
    data = _read(git / "objects" / sha[:2] / sha[2:], MAX_COMMIT_BYTES)
    if data is None:
        return None
    inflated = _inflate(data)
    if inflated is None or not inflated.startswith(b"commit "):
        return None
    return inflated.partition(b"\0")[2]


def _pack_offset(index: bytes, sha: bytes) -> int | None:
    """The offset of ``sha`` in the pack of a version 2 index, None when it is not there."""
    if len(index) < 8 + 256 * 4 or index[:4] != PACK_INDEX_MAGIC or index[4:8] != b"\0\0\0\2":
        return None
    fanout = 8
    count = int.from_bytes(index[fanout + 255 * 4 : fanout + 256 * 4], "big")
    names = fanout + 256 * 4
    crcs = names + 20 * count
    offsets = crcs + 4 * count
    if len(index) < offsets + 4 * count:
        return None
    first = sha[0]
    low = int.from_bytes(index[fanout + (first - 1) * 4 : fanout + first * 4], "big") if first else 0
    high = int.from_bytes(index[fanout + first * 4 : fanout + (first + 1) * 4], "big")
    while low < high:
        middle = (low + high) // 2
        found = index[names + 20 * middle : names + 20 * middle + 20]
        if found == sha:
            offset = int.from_bytes(index[offsets + 4 * middle : offsets + 4 * middle + 4], "big")
            if offset & 0x80000000:
                large = offsets + 4 * count + 8 * (offset & 0x7FFFFFFF)
                return int.from_bytes(index[large : large + 8], "big") if len(index) >= large + 8 else None
            return offset
        if found < sha:
            low = middle + 1
        else:
            high = middle
    return None


def _packed(git: Path, sha: str) -> bytes | None:
    pack_folder = git / "objects" / "pack"
    try:
        indexes = sorted(name for name in os.listdir(pack_folder) if name.endswith(".idx"))
    except OSError:
        return None
    wanted = bytes.fromhex(sha)
    for name in indexes[:64]:
        index = _read(pack_folder / name, MAX_INDEX_BYTES)
        offset = _pack_offset(index or b"", wanted)
        if offset is None:
            continue
        data = _read(pack_folder / (name[: -len(".idx")] + ".pack"), MAX_COMMIT_BYTES + 32, offset)
        if not data:
            return None
        kind = (data[0] >> 4) & 7
        at = 1
        while data[at - 1] & 0x80 and at < len(data):
            at += 1
        if kind != COMMIT_TYPE:
            return None  # a delta: not read (rare for commits); the time stays unknown
        return _inflate(data[at:])
    return None


def commit_time(repository: Path) -> datetime | None:
    """The committer time of ``repository``'s checked-out commit, with its zone; None when unknown."""
    sha = head_commit(repository)
    if sha is None:
        return None
    git = repository / GIT_FOLDER
    text = sha.decode()
    body = _loose(git, text) or _packed(git, text)
    if body is None:
        return None
    header = body.partition(b"\n\n")[0]
    found = COMMITTER.search(header)
    if found is None:
        return None
    seconds, sign, hours, minutes = int(found[1]), found[2], int(found[3]), int(found[4])
    offset = timedelta(hours=hours, minutes=minutes) * (-1 if sign == b"-" else 1)
    try:
        return datetime.fromtimestamp(seconds, timezone(offset))
    except (OverflowError, OSError, ValueError):
        return None
