"""Reading a class folder safely: regular files only, never out of the folder, zips read into scratch.

A download is hostile input. The walk never follows a symbolic link, refuses links, hard links, devices,
FIFOs and sockets with a reason, and reads zips (the LMS's own, and zips students put inside it) entry by
entry into a scratch folder within size, count and ratio limits: names that are absolute or climb out
(``../``), symlink entries and encrypted entries are refused. A zip appears in the tree as a folder named
like the zip (``alice.zip/opengym.py``), so layouts see its entries as the student's files.
"""

from __future__ import annotations

import os
import stat
import zipfile
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

from grader.classroom.model import Skipped


@dataclass(frozen=True)
class Limits:
    """Bounds on what a download may make the grader read or write.

    Attributes:
        max_files: Files (and zip entries) in the whole download.
        max_file_bytes: Bytes of one file or one extracted entry.
        max_total_bytes: Bytes extracted from zips, all together.
        max_ratio: Uncompressed / compressed size of one zip entry (zip bombs go far past it).
        max_zip_depth: Zips inside zips.
        max_depth: Folder depth.
    """

    max_files: int = 20_000
    max_file_bytes: int = 50 * 2**20
    max_total_bytes: int = 1 * 2**30
    max_ratio: float = 200.0
    max_zip_depth: int = 3
    max_depth: int = 32


@dataclass(frozen=True)
class Entry:
    """A regular file of the download: its ``/``-separated path in the download and its place on disk."""

    relative: str
    path: Path

    @property
    def parts(self) -> tuple[str, ...]:
        """The path's components."""
        return tuple(self.relative.split("/"))

    @property
    def name(self) -> str:
        """The file's own name."""
        return self.relative.rsplit("/", 1)[-1]


@dataclass
class Budget:
    """What the downloads of one command have used of `Limits` so far: one budget for every download it
    reads (several targets together), so that the limits hold "in all".

    Attributes:
        files: Files and zip entries taken.
        extracted_bytes: Bytes written into scratch from zips.
    """

    files: int = 0
    extracted_bytes: int = 0


@dataclass
class Tree:
    """The regular files of a download (zips opened), with what was refused and how much was ignored."""

    root: Path
    entries: list[Entry] = field(default_factory=list)
    refused: list[Skipped] = field(default_factory=list)
    ignored: int = 0
    budget: Budget = field(default_factory=Budget)

    def take(self, entry: Entry) -> None:
        """Add a file of the download, counted against the budget."""
        self.entries.append(entry)
        self.budget.files += 1


def ignorable(name: str) -> bool:
    """Names skipped without a word: macOS resource forks, hidden files and folders, Jupyter checkpoints."""
    return name.startswith(".") or name == "__MACOSX" or name == "__pycache__"


def read_tree(
    root: Path, scratch: Path | None, limits: Limits | None = None, budget: Budget | None = None
) -> Tree:
    """Every regular file under ``root`` (a folder or a zip), zips opened into ``scratch``.

    Args:
        root: The class folder, or a zip as downloaded.
        scratch: A folder (created, should be empty) that zips are read into; None refuses every zip.
        limits: Size and count bounds.
        budget: What other downloads of the same command used already (shared, updated); a fresh one
            when None.

    Returns:
        The files, sorted by path, and the refusals.
    """
    limits = limits or Limits()
    tree = Tree(root=root, budget=budget if budget is not None else Budget())
    if root.is_symlink():
        tree.refused.append(Skipped(root.name, "a symbolic link: pass the folder or file itself"))
        return tree
    if root.is_file() and root.suffix.lower() != ".zip":
        tree.take(Entry(root.name, root))
        return tree
    if root.is_file():
        if scratch is None:
            tree.refused.append(Skipped(root.name, "a zip needs a scratch folder to be read into"))
            return tree
        _expand_zip(tree, root, "", scratch / "download", limits, depth=1)
    else:
        _walk(tree, root, "", scratch, limits, depth=0)
    tree.entries.sort(key=lambda entry: entry.relative)
    return tree


def _walk(tree: Tree, folder: Path, prefix: str, scratch: Path | None, limits: Limits, depth: int) -> None:
    if depth > limits.max_depth:
        tree.refused.append(Skipped(prefix or ".", f"deeper than {limits.max_depth} folders"))
        return
    try:
        with os.scandir(folder) as listing:
            items = sorted(listing, key=lambda item: item.name)
    except OSError as error:
        tree.refused.append(Skipped(prefix or ".", f"cannot be listed ({error.strerror})"))
        return
    for item in items:
        relative = f"{prefix}{item.name}"
        if ignorable(item.name):
            tree.ignored += 1
            continue
        try:
            info = item.stat(follow_symlinks=False)
        except OSError as error:
            tree.refused.append(Skipped(relative, f"cannot be read ({error.strerror})"))
            continue
        if stat.S_ISLNK(info.st_mode):
            tree.refused.append(
                Skipped(relative, f"a symbolic link (to {_link_target(item.path)}): links are never followed")
            )
        elif stat.S_ISDIR(info.st_mode):
            _walk(tree, Path(item.path), f"{relative}/", scratch, limits, depth + 1)
        elif not stat.S_ISREG(info.st_mode):
            tree.refused.append(Skipped(relative, "not a regular file (a device, FIFO or socket)"))
        elif info.st_nlink > 1:
            tree.refused.append(
                Skipped(
                    relative,
                    f"a hard link ({info.st_nlink} names for one file, possibly outside the class folder)",
                )
            )
        elif info.st_size > limits.max_file_bytes:
            tree.refused.append(
                Skipped(relative, f"{info.st_size:,} bytes, over the {limits.max_file_bytes:,} limit")
            )
        elif tree.budget.files >= limits.max_files:
            tree.refused.append(Skipped(relative, f"over the {limits.max_files:,}-file limit of a download"))
        elif item.name.lower().endswith(".zip") and scratch is not None:
            _expand_zip(
                tree,
                Path(item.path),
                f"{relative}/",
                scratch / f"z{len(tree.entries)}-{len(tree.refused)}",
                limits,
                depth=1,
            )
        else:
            tree.take(Entry(relative, Path(item.path)))


def _link_target(path: str) -> str:
    try:
        return os.readlink(path)
    except OSError:
        return "?"


def _expand_zip(tree: Tree, archive: Path, prefix: str, dest: Path, limits: Limits, depth: int) -> None:
    label = prefix.rstrip("/") or archive.name
    if depth > limits.max_zip_depth:
        tree.refused.append(Skipped(label, f"a zip nested deeper than {limits.max_zip_depth} zips"))
        return
    try:
        with zipfile.ZipFile(archive) as bundle:
            members = bundle.infolist()
            dest.mkdir(parents=True, exist_ok=True)
            for number, member in enumerate(members):
                if tree.budget.files >= limits.max_files and not member.is_dir():
                    left = sum(1 for rest in members[number:] if not rest.is_dir())
                    tree.refused.append(
                        Skipped(
                            label,
                            f"{left:,} entries not read: over the {limits.max_files:,}-file limit of a download",  # noqa: E501
                        )
                    )
                    break
                _extract_member(tree, bundle, member, prefix, dest, number, limits, depth)
    except (zipfile.BadZipFile, OSError, EOFError, NotImplementedError, RuntimeError) as error:
        tree.refused.append(Skipped(label, f"not a readable zip ({type(error).__name__}: {error})"))


def _safe_name(name: str) -> tuple[str, ...] | str:
    """The entry's path components, or why the name is refused."""
    if "\x00" in name:
        return "a name with a NUL byte"
    normalised = name.replace("\\", "/")
    if normalised.startswith("/") or (len(normalised) > 1 and normalised[1] == ":"):
        return "an absolute name (it would be written outside the scratch folder)"
    parts = tuple(part for part in PurePosixPath(normalised).parts if part not in ("", "."))
    if ".." in parts:
        return "a name climbing out of the zip with ../ (path traversal)"
    return parts


def _extract_member(
    tree: Tree,
    bundle: zipfile.ZipFile,
    member: zipfile.ZipInfo,
    prefix: str,
    dest: Path,
    number: int,
    limits: Limits,
    depth: int,
) -> None:
    parts = _safe_name(member.filename)
    where = f"{prefix}{member.filename}"
    if isinstance(parts, str):
        tree.refused.append(Skipped(where, parts))
        return
    if member.is_dir() or not parts:
        return
    if any(ignorable(part) for part in parts):
        tree.ignored += 1
        return
    mode = member.external_attr >> 16
    if stat.S_ISLNK(mode):
        tree.refused.append(Skipped(where, "a symbolic link stored in the zip: links are never followed"))
        return
    if stat.S_IFMT(mode) and not stat.S_ISREG(mode) and not stat.S_ISDIR(mode):
        tree.refused.append(Skipped(where, "not a regular file in the zip (a device, FIFO or socket)"))
        return
    if member.flag_bits & 0x1:
        tree.refused.append(Skipped(where, "encrypted: it cannot be read without the password"))
        return
    if member.file_size > limits.max_file_bytes:
        tree.refused.append(
            Skipped(where, f"{member.file_size:,} bytes, over the {limits.max_file_bytes:,} limit")
        )
        return
    if member.file_size > limits.max_ratio * max(member.compress_size, 1) and member.file_size > 2**20:
        tree.refused.append(
            Skipped(
                where,
                f"compressed {member.file_size / max(member.compress_size, 1):,.0f} to 1, over the {limits.max_ratio:g}:1 limit (a zip bomb?)",  # noqa: E501
            )
        )
        return
    if tree.budget.extracted_bytes + member.file_size > limits.max_total_bytes:
        tree.refused.append(
            Skipped(where, f"the download's zips expand past {limits.max_total_bytes:,} bytes")
        )
        return
    # Written under a numbered name: the entry's own name never reaches the file system.
    target = dest / f"{number}{Path(parts[-1]).suffix[:16]}"
    written = _copy_bounded(bundle, member, target, limits.max_file_bytes)
    if written is None:
        tree.refused.append(Skipped(where, "its data is larger than its header says (a zip bomb?)"))
        target.unlink(missing_ok=True)
        return
    tree.budget.extracted_bytes += written
    relative = prefix + "/".join(parts)
    if parts[-1].lower().endswith(".zip"):
        _expand_zip(tree, target, f"{relative}/", dest / f"{number}.d", limits, depth + 1)
    else:
        tree.take(Entry(relative, target))


def _copy_bounded(bundle: zipfile.ZipFile, member: zipfile.ZipInfo, target: Path, limit: int) -> int | None:
    """Copy an entry, stopping past ``limit`` bytes or past its declared size; None when it lied."""
    written = 0
    with bundle.open(member) as source, target.open("wb") as sink:
        while chunk := source.read(65536):
            written += len(chunk)
            if written > min(limit, member.file_size):
                return None
            sink.write(chunk)
    return written
