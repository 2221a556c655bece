"""Read a submitted file without following links: opened once, checked and read from the descriptor.

A student chooses what an upload holds, links included: an ``opengym.py`` that is a symbolic link to the
autograder's seed secret, or a hard link to it, would otherwise be read by the grader (which may run as
root) and run as the student's code. So a submitted file is opened without following a symbolic link
(``O_NOFOLLOW`` where the system has it; elsewhere ``lstat`` before and ``fstat`` after opening must name
the same file), every folder below a given root is opened the same way, and the opened descriptor must be
a regular file with one name; the bytes are read from that descriptor, never by path again, so nothing can
be swapped in between the check and the read.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from grader.errors import GraderError

_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
"""0 where the system has no ``O_NOFOLLOW`` (Windows): ``lstat``/``fstat`` stand in for it."""
_NONBLOCK = getattr(os, "O_NONBLOCK", 0)
"""Opening a FIFO for reading waits for a writer; this returns at once (and ``fstat`` refuses it)."""
_DIRECTORY = getattr(os, "O_DIRECTORY", 0)
_BINARY = getattr(os, "O_BINARY", 0)


class UnsafeFile(GraderError):
    """Raised when a submitted file is a link, not a regular file, or cannot be read; the message says
    what was found and what to do."""


def read_untrusted(path: Path, *, limit: int, root: Path | None = None, one_name: bool = True) -> bytes:
    """The first ``limit + 1`` bytes of a submitted file, read without following any link.

    Args:
        path: The file.
        limit: The most bytes a caller accepts; one more is read so that the caller sees a file is over.
        root: A trusted folder ``path`` lies in: every folder between it and the file is opened without
            following links too (a folder of the upload that is a link is refused). None: only the file's
            own name is checked (the folders are the user's own choice, as in ``gymgrade check FILE``).
        one_name: Refuse a file with several names (a hard link); False for the grader's own files (a
            student's hard link to the bundle's secret must not stop the grader from reading it).

    Raises:
        UnsafeFile: The file (or a folder below ``root``) is a symbolic link, the file has several names
            (a hard link), is not a regular file, or cannot be opened or read.
    """
    descriptor = _open(path, root)
    try:
        info = os.fstat(descriptor)
        _check_opened(path, info, one_name)
        # One read asks for everything (a regular file gives it at once, so the bytes are never copied);
        # the loop only continues a read the system cut short.
        chunks = [os.read(descriptor, min(limit + 1, info.st_size + 1))]
        remaining = limit + 1 - len(chunks[0])
        while remaining > 0 and chunks[-1]:
            chunks.append(os.read(descriptor, min(remaining, 1 << 20)))
            remaining -= len(chunks[-1])
        return b"".join(chunks) if any(chunks[1:]) else chunks[0]
    except OSError as error:
        raise UnsafeFile(_unreadable(path, error)) from error
    finally:
        os.close(descriptor)


def _open(path: Path, root: Path | None) -> int:
    flags = os.O_RDONLY | _NOFOLLOW | _NONBLOCK | _BINARY
    if root is None or not _NOFOLLOW or os.open not in os.supports_dir_fd:
        if root is not None:
            _check_folders_by_name(path, root)
        before = _lstat(path)
        descriptor = _open_or_refuse(path, path, flags)
        if not _NOFOLLOW and not os.path.samestat(before, os.fstat(descriptor)):
            os.close(descriptor)
            raise UnsafeFile(
                f"{path.name} changed while it was being opened: it was not read. Submit it again."
            )
        return descriptor
    parts = path.relative_to(root).parts
    folder = os.open(root, os.O_RDONLY | _DIRECTORY)
    try:
        for number, part in enumerate(parts[:-1]):
            below = _open_or_refuse(
                root.joinpath(*parts[: number + 1]), part, os.O_RDONLY | _DIRECTORY | _NOFOLLOW, folder
            )
            os.close(folder)
            folder = below
        return _open_or_refuse(path, parts[-1], flags, folder)
    finally:
        os.close(folder)


def _open_or_refuse(path: Path, name: str | Path, flags: int, folder: int | None = None) -> int:
    """``os.open(name, flags, dir_fd=folder)``; a refusal naming ``path`` when it fails (a link, mostly)."""
    try:
        return os.open(name, flags, dir_fd=folder)
    except OSError as error:
        if _is_link(path):
            raise UnsafeFile(_link_message(path)) from error
        raise UnsafeFile(_unreadable(path, error)) from error


def _check_folders_by_name(path: Path, root: Path) -> None:
    current = root
    for part in path.relative_to(root).parts[:-1]:
        current = current / part
        if _is_link(current):
            raise UnsafeFile(_link_message(current))


def _lstat(path: Path) -> os.stat_result:
    try:
        info = path.lstat()
    except OSError as error:
        raise UnsafeFile(_unreadable(path, error)) from error
    if stat.S_ISLNK(info.st_mode):
        raise UnsafeFile(_link_message(path))
    return info


def _check_opened(path: Path, info: os.stat_result, one_name: bool) -> None:
    if not stat.S_ISREG(info.st_mode):
        raise UnsafeFile(
            f"{path.name} is not a regular file (a folder, device, FIFO or socket): it was not read. "
            "Submit the .py or .ipynb file itself."
        )
    if one_name and info.st_nlink > 1:
        raise UnsafeFile(
            f"{path.name} is a hard link ({info.st_nlink} names for one file, possibly outside the submission): "  # noqa: E501
            "it was not read. Submit a copy of the file itself."
        )


def _is_link(path: Path) -> bool:
    try:
        return stat.S_ISLNK(path.lstat().st_mode)
    except OSError:
        return False


def _link_message(path: Path) -> str:
    try:
        target = os.readlink(path)
    except OSError:
        target = "?"
    return (
        f"{path.name} is a symbolic link (to {target}): links are never followed, so it was not read. "
        "Submit the file itself, not a link to it."
    )


def _unreadable(path: Path, error: OSError) -> str:
    return (
        f"{path.name} could not be read ({error.strerror or error}): "
        "check that the file exists and is readable."
    )
