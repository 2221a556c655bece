"""Where the submissions are and what text each holds: the one adapter from a class folder to documents.

`submissions_from` is the single place that knows a class layout. It reads plain folders: one folder per
student (every ``.py``/``.ipynb`` inside is theirs) or one file per student in a flat folder. The class
layouts of learning platforms (grader/classroom/) plug in here by replacing this one function.
"""

from __future__ import annotations

import ast
import json
from dataclasses import dataclass
from pathlib import Path

from grader.notebook import MAX_NOTEBOOK_BYTES
from grader.similarity.errors import ClassDirectoryError

SOURCE_SUFFIXES = (".py", ".ipynb")
MAX_COMPARED_BYTES = 200_000
"""A lab solution is under 30 KB; parsing a megabyte of padding costs seconds, so larger Python is left out
(the grader itself accepts up to ``grader.validation.MAX_SUBMISSION_BYTES``)."""
MAX_FILES_PER_SUBMISSION = 20
"""A student's folder may hold helpers beside the lab file; files beyond this many are listed, not read."""
IGNORED_PARTS = ("__pycache__", ".ipynb_checkpoints", "__MACOSX")


@dataclass(frozen=True)
class SourceText:
    """One file's Python text as compared (a notebook's code cells, IPython magics blanked out).

    Attributes:
        path: The file.
        text: Its Python source; the line numbers of this text are the ones reports cite.
        notes: What was left out of it (a notebook's cells that are not Python).
    """

    path: Path
    text: str
    notes: tuple[str, ...] = ()


@dataclass(frozen=True)
class Unreadable:
    """Why a file was left out of the comparison.

    Attributes:
        path: The file.
        reason: What was expected, what was found, what to do.
    """

    path: Path
    reason: str


def submissions_from(path: Path) -> list[tuple[str, Path]]:
    """The submissions of a class folder as ``(identity, source file)`` pairs, sorted.

    A sub-folder is one student (identity: the folder's name) and every ``.py``/``.ipynb`` file in it,
    at any depth, is theirs (a student may appear in several pairs). A ``.py``/``.ipynb`` file directly
    in ``path`` is one student (identity: the file name without its suffix). Hidden files, caches and
    notebook checkpoints are skipped.

    Raises:
        ClassDirectoryError: When ``path`` is not a directory.
    """
    if not path.is_dir():
        raise ClassDirectoryError(
            f"expected a class folder (one sub-folder or one file per student), found {_what(path)} at {path}; "  # noqa: E501
            "pass the folder the submissions were downloaded into"
        )
    found: list[tuple[str, Path]] = []
    for entry in sorted(path.iterdir()):
        if _ignored(entry.name):
            continue
        if entry.is_dir() and not entry.is_symlink():
            files = [file for file in sorted(entry.rglob("*")) if _is_source(file, entry)]
            found.extend((entry.name, file) for file in files)
            if not files:
                found.append((entry.name, entry))
        elif entry.is_file() or entry.is_symlink():
            found.append((entry.stem if _has_source_suffix(entry) else entry.name, entry))
    return found


def references_from(path: Path) -> list[tuple[str, Path]]:
    """Every ``.py``/``.ipynb`` file under a --reference folder, each a document named ``folder/path``.

    Raises:
        ClassDirectoryError: When ``path`` is not a directory.
    """
    if not path.is_dir():
        raise ClassDirectoryError(
            f"expected a folder of known solutions for --reference, found {_what(path)} at {path}; "
            "pass a folder holding .py or .ipynb files"
        )
    return [
        (f"{path.name}/{file.relative_to(path).as_posix()}", file)
        for file in sorted(path.rglob("*"))
        if _is_source(file, path)
    ]


def read_source(path: Path) -> SourceText | Unreadable:
    """Read one submitted file as Python text, bounded in size, never executing or importing it."""
    if path.is_symlink():
        return Unreadable(path, f"{path.name} is a symbolic link: only regular files are read, left out.")
    if path.is_dir():
        return Unreadable(path, f"{path.name} holds no .py or .ipynb file: nothing to compare.")
    if not _has_source_suffix(path):
        return Unreadable(
            path,
            f"{path.name} is neither a .py nor an .ipynb file: only Python sources and notebooks are compared.",  # noqa: E501
        )
    notebook = path.suffix.lower() == ".ipynb"
    limit = MAX_NOTEBOOK_BYTES if notebook else MAX_COMPARED_BYTES
    try:
        with path.open("rb") as stream:
            data = stream.read(limit + 1)
    except OSError as error:
        return Unreadable(path, f"{path.name} could not be read ({error.strerror or error}).")
    if len(data) > limit:
        return Unreadable(
            path, f"{path.name} is larger than {limit:,} bytes: too large to be a lab solution, left out."
        )
    if not data.strip():
        return Unreadable(path, f"{path.name} is empty: nothing to compare.")
    if b"\0" in data:
        return Unreadable(path, f"{path.name} is binary (it contains NUL bytes), not Python text: left out.")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        return Unreadable(
            path, f"{path.name} is not UTF-8 text (byte {error.start} cannot be decoded): left out."
        )
    if notebook:
        return _notebook_code(path, text)
    return SourceText(path, text)


def _notebook_code(path: Path, text: str) -> SourceText | Unreadable:
    try:
        notebook = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as error:
        return Unreadable(
            path, f"{path.name} is not a readable notebook: not valid JSON ({str(error)[:120]})."
        )
    cells = notebook.get("cells") if isinstance(notebook, dict) else None
    if not isinstance(cells, list):
        return Unreadable(
            path, f'{path.name} is JSON but not a Jupyter notebook (no "cells" list): left out.'
        )
    chunks: list[str] = []
    notes: list[str] = []
    for number, cell in enumerate(cells, start=1):
        if not isinstance(cell, dict) or cell.get("cell_type") != "code":
            continue
        source = cell.get("source", "")
        if isinstance(source, list):
            source = "".join(part for part in source if isinstance(part, str))
        if isinstance(source, str) and source.strip():
            lines = [_without_magic(line) for line in source.splitlines()]
            if not _parses("\n".join(lines)):
                # one broken cell (a half-typed line) must not hide the rest of the notebook
                notes.append(f"{path.name}: cell {number} is not valid Python and was not compared.")
                lines = [""] * len(lines)
            chunks.append("\n".join(lines))
    code = "\n\n".join(chunks)
    if len(code.encode()) > MAX_COMPARED_BYTES:
        return Unreadable(
            path,
            f"{path.name}'s code cells hold more than {MAX_COMPARED_BYTES:,} bytes: too large, left out.",
        )
    if not code.strip():
        return Unreadable(path, f"{path.name} has no code cells: nothing to compare.")
    return SourceText(path, code + "\n", tuple(notes))


def _parses(code: str) -> bool:
    try:
        ast.parse(code)
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        return False
    return True


def _without_magic(line: str) -> str:
    # IPython magics and shell escapes are not Python; blanking keeps every other line's number.
    return "" if line.lstrip().startswith(("%", "!")) else line


def _ignored(name: str) -> bool:
    return name.startswith(".") or name in IGNORED_PARTS


def _has_source_suffix(path: Path) -> bool:
    return path.suffix.lower() in SOURCE_SUFFIXES


def _is_source(file: Path, root: Path) -> bool:
    parts = file.relative_to(root).parts
    return (
        (file.is_file() or file.is_symlink())
        and _has_source_suffix(file)
        and not any(_ignored(part) for part in parts)
    )


def _what(path: Path) -> str:
    if not path.exists():
        return "nothing"
    return "a file" if path.is_file() else "something else"
