"""The reference index cache: each reference file is indexed once, keyed by its text, and trusted only so far.

An entry is ``<blake2b of INDEX_VERSION and the text>.json`` holding a `CacheEntry`: the SHA-256 of the text
it indexes and its `IndexedFile`. A new version of the normaliser or the winnowing changes ``INDEX_VERSION``
and with it every key. The cache is a folder one user account owns, and it is used only that way:

- the folder must be owned by the user running gymgrade and writable by no one else; otherwise the run goes
  on without it (with a note), so another account cannot plant entries that hide a copied reference;
- an entry is read without following links, must be a regular file of that user, writable by no one else,
  at most ``MAX_ENTRY_BYTES``; it must name the SHA-256 of the very text looked up (an entry copied or
  renamed from another file cannot stand for these bytes) and its lists must agree; a bad entry is indexed
  again, rewritten, and noted in the report;
- an entry is written under a fresh random temporary name created with ``O_CREAT | O_EXCL | O_NOFOLLOW``
  (mode 0600) inside the folder opened once as a descriptor, then renamed: a link planted at any name is
  never written through.

POSIX-leaning: where the platform lacks ``O_NOFOLLOW``, descriptor-relative calls or user ids (Windows),
the same steps run by path and the ownership checks are skipped.
"""

from __future__ import annotations

import errno
import hashlib
import os
import secrets
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from pydantic import BaseModel, ConfigDict, ValidationError

from grader.classroom.similarity.document import IndexedFile
from grader.classroom.similarity.winnow import WINDOW, K

INDEX_VERSION = f"2-k{K}-w{WINDOW}"
MAX_ENTRY_BYTES = 64 * 2**20
"""Largest entry read: the index of a 200 KB file (``MAX_COMPARED_BYTES``) is a few MB at most."""

_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_DIRECTORY = getattr(os, "O_DIRECTORY", 0)
_BINARY = getattr(os, "O_BINARY", 0)
_BY_DESCRIPTOR = os.open in os.supports_dir_fd and os.rename in os.supports_dir_fd and bool(_DIRECTORY)
_USER = os.geteuid() if hasattr(os, "geteuid") else None
_WRITABLE_BY_OTHERS = stat.S_IWGRP | stat.S_IWOTH


class CacheEntry(BaseModel):
    """What one entry file holds: the SHA-256 of the text it indexes, and the index."""

    model_config = ConfigDict(extra="forbid")

    sha256: str
    index: IndexedFile


def default_cache_dir() -> Path:
    """``$XDG_CACHE_HOME/gymgrade/similarity`` (``~/.cache/gymgrade/similarity`` by default)."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "gymgrade" / "similarity"


def cache_key(text: str) -> str:
    """The entry name of a file's text."""
    return hashlib.blake2b(f"{INDEX_VERSION}\0{text}".encode(), digest_size=20).hexdigest()


def text_digest(text: str) -> str:
    """The SHA-256 of ``text`` an entry must name."""
    return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()


def inconsistency(index: IndexedFile) -> str | None:
    """Why an index cannot be what `index_text` returned for some file, or None when its parts agree."""
    units = len(index.shapes)
    if len(index.unit_names) != units:
        return f"{units} unit shapes but {len(index.unit_names)} unit names"
    if index.reason is not None and (units or index.fingerprints or index.remarks or index.constants):
        return "a file left out that still has an index"
    last = max(index.lines, 1)
    for _hash, unit, first, end in index.fingerprints:
        if not (0 <= unit < units and 0 <= first <= end <= last):
            return f"a fingerprint of unit {unit}, lines {first}-{end}, outside the file's {units} units and {index.lines} lines"  # noqa: E501
    if any(not 0 <= line <= last for *_rest, line in index.remarks) or any(
        not 0 <= line <= last for _value, line in index.constants
    ):
        return f"a remark or constant outside the file's {index.lines} lines"
    return None


class IndexCache:
    """Indexed reference files on disk, one JSON file per distinct text (see the module's rules).

    Attributes:
        directory: The cache folder.
        hits: Entries used.
        misses: Texts indexed again (no entry, or an entry not trusted).
        notes: What the report should say about entries or a folder that were not trusted.
    """

    def __init__(self, directory: Path) -> None:
        self.directory = directory
        self.hits = 0
        self.misses = 0
        self.notes: list[str] = []
        self._refused = False

    def get(self, text: str, name: str = "") -> IndexedFile | None:
        """The cached index of ``text`` (a file called ``name``), or None when there is none or it is not
        trusted (then a note says why, and the caller indexes the text again)."""
        key = cache_key(text)
        with self._folder(create=False) as folder:
            found = None if folder is None else folder.read(f"{key}.json")
        if not isinstance(found, bytes):
            if found is not None:
                self._note(f"the cache entry of {name or key} was not used ({found}); it was indexed again")
            self.misses += 1
            return None
        try:
            entry = CacheEntry.model_validate_json(found)
        except (ValidationError, ValueError) as error:
            problem: str | None = f"not a cache entry: {str(error).splitlines()[0]}"
        else:
            problem = inconsistency(entry.index)
            if entry.sha256 != text_digest(text):
                problem = "it is the index of another text"
        if problem is not None:
            self._note(f"the cache entry of {name or key} was not used ({problem}); it was indexed again")
            self.misses += 1
            return None
        self.hits += 1
        return entry.index

    def put(self, text: str, indexed: IndexedFile) -> None:
        """Store an index: written whole under a fresh name no link can stand at, then renamed, so a
        concurrent reader never sees half an entry. A cache that cannot be written only costs time."""
        data = CacheEntry(sha256=text_digest(text), index=indexed).model_dump_json().encode()
        with self._folder(create=True) as folder:
            if folder is not None:
                folder.write(f"{cache_key(text)}.json", data)

    def _note(self, note: str) -> None:
        if note not in self.notes:
            self.notes.append(note)

    @contextmanager
    def _folder(self, *, create: bool) -> Iterator[_Folder | None]:
        """The cache folder, opened once (as a descriptor where the platform allows), or None when it is
        missing, cannot be opened, or is not this user's own (then noted once and never used again)."""
        if self._refused:
            yield None
            return
        if create:
            try:
                self.directory.mkdir(mode=0o700, parents=True, exist_ok=True)
            except OSError:
                yield None
                return
        try:
            descriptor = (
                os.open(self.directory, os.O_RDONLY | _DIRECTORY | _BINARY) if _BY_DESCRIPTOR else None
            )
        except OSError:
            yield None
            return
        try:
            yield self._checked(descriptor)
        finally:
            if descriptor is not None:
                os.close(descriptor)

    def _checked(self, descriptor: int | None) -> _Folder | None:
        try:
            info = os.fstat(descriptor) if descriptor is not None else os.stat(self.directory)
        except OSError:
            return None
        why = _not_own(info, "folder") or (None if stat.S_ISDIR(info.st_mode) else "it is not a folder")
        if why is None:
            return _Folder(self.directory, descriptor)
        self._refused = True
        self._note(
            f"the similarity cache {self.directory} was not used ({why}); every reference was indexed "
            "again: pass --cache with a folder of your own"
        )
        return None


class _Folder:
    """The cache folder's files, reached through its descriptor (or its path where there is none)."""

    def __init__(self, path: Path, descriptor: int | None) -> None:
        self.path = path
        self.descriptor = descriptor

    def _open(self, name: str, flags: int, mode: int = 0o600) -> int:
        if self.descriptor is not None:
            return os.open(name, flags | _NOFOLLOW | _BINARY, mode, dir_fd=self.descriptor)
        return os.open(self.path / name, flags | _NOFOLLOW | _BINARY, mode)

    def read(self, name: str) -> bytes | str | None:
        """The entry's bytes, None when there is none, or why it is not read."""
        try:
            handle = self._open(name, os.O_RDONLY)
        except FileNotFoundError:
            return None
        except OSError as error:
            return "a symbolic link" if _is_link(error) else f"cannot be read ({error.strerror})"
        with os.fdopen(handle, "rb") as stream:
            info = os.fstat(stream.fileno())
            why = _not_own(info, "file")
            if why is not None:
                return why
            if not stat.S_ISREG(info.st_mode):
                return "not a regular file"
            if info.st_size > MAX_ENTRY_BYTES:
                return f"{info.st_size:,} bytes, over the {MAX_ENTRY_BYTES:,} limit"
            data = stream.read(MAX_ENTRY_BYTES + 1)
            return data if len(data) <= MAX_ENTRY_BYTES else f"over the {MAX_ENTRY_BYTES:,}-byte limit"

    def write(self, name: str, data: bytes) -> None:
        temporary = f".{name}.{secrets.token_hex(8)}.tmp"
        try:
            handle = self._open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL)
        except OSError:
            return
        try:
            with os.fdopen(handle, "wb") as stream:
                stream.write(data)
            if self.descriptor is not None:
                os.rename(temporary, name, src_dir_fd=self.descriptor, dst_dir_fd=self.descriptor)
            else:
                os.replace(self.path / temporary, self.path / name)
        except OSError:
            try:
                if self.descriptor is not None:
                    os.unlink(temporary, dir_fd=self.descriptor)
                else:
                    (self.path / temporary).unlink()
            except OSError:
                pass


def _not_own(info: os.stat_result, what: str) -> str | None:
    """Why a file or folder with ``info`` is not this user's own, or None (always None without user ids)."""
    if _USER is None:
        return None
    if info.st_uid != _USER:
        return f"the {what} belongs to user id {info.st_uid}, not to this user ({_USER})"
    if info.st_mode & _WRITABLE_BY_OTHERS:
        return f"the {what} is writable by other users (mode {stat.S_IMODE(info.st_mode):o})"
    return None


def _is_link(error: OSError) -> bool:
    return error.errno in (errno.ELOOP, getattr(errno, "EMLINK", -1))
