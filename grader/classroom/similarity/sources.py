"""Where the submissions are and what text each holds: the one adapter from a class download to documents.

`submissions_from` is the single place that knows a class layout, and it knows none itself: it asks
grader/classroom/ (the same discovery `gymgrade grade` uses), so every layout grading takes (plain folders,
Canvas, Gradescope exports, GitHub Classroom, Moodle, nbgrader, Blackboard, zips of them) is compared, one
document per student keyed by the gradebook's identity. A student's document is every candidate file of
theirs (``grader.classroom.graded_file.is_candidate``: Python or a notebook, never a test, checkpoint or
setup file), the graded file first; docs/similarity.md says why not the graded file alone.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

from grader import parsing
from grader.classroom import ClassDownload, GradedFileRule, discover
from grader.classroom.graded_file import is_candidate
from grader.classroom.model import Skipped
from grader.classroom.similarity.errors import ClassDirectoryError
from grader.classroom.similarity.report import UnreadableFile
from grader.submission.notebook import MAX_NOTEBOOK_BYTES, read_notebook
from grader.submission.untrusted_file import UnsafeFile, read_untrusted
from grader.submission.validation import FileVerdict

SOURCE_SUFFIXES = (".py", ".ipynb")
MAX_COMPARED_BYTES = 200_000
"""A lab solution is under 30 KB; parsing a megabyte of padding costs seconds, so larger Python is left out
(the grader itself accepts up to ``grader.submission.validation.MAX_SUBMISSION_BYTES``)."""
MAX_FILES_PER_SUBMISSION = 20
"""A student's folder may hold helpers beside the lab file; files beyond this many are listed, not read."""
MAX_REFUSED_LISTED = 20
"""Refused files listed per student (and for nobody); the rest are counted in one line."""
IGNORED_PARTS = ("__pycache__", ".ipynb_checkpoints", "__MACOSX")
UNATTRIBUTED = "(not attributed)"
"""The identity column of a file no student can be named for."""
REFUSED = "(refused)"
"""The identity column of a file refused for safety that no student can be named for."""


@dataclass(frozen=True)
class SourceText:
    """One file's Python text as compared (a notebook's code cells, IPython magics blanked out).

    Attributes:
        path: The file.
        text: Its Python source; the line numbers of this text are the ones reports cite.
        notes: What was left out of it (a notebook's cells that are not Python).
        name: Its own name as shown (a class's zip is read into numbered files); ``path.name`` when empty.
    """

    path: Path
    text: str
    notes: tuple[str, ...] = ()
    name: str = ""

    @property
    def shown_name(self) -> str:
        """The file's name as a person reads it."""
        return self.name or self.path.name


@dataclass(frozen=True)
class Unreadable:
    """Why a file was left out of the comparison.

    Attributes:
        path: The file.
        reason: What was expected, what was found, what to do.
        name: Its own name as shown; ``path.name`` when empty.
    """

    path: Path
    reason: str
    name: str = ""

    @property
    def shown_name(self) -> str:
        """The file's name as a person reads it."""
        return self.name or self.path.name


@dataclass
class ClassSources:
    """The documents of a class: each student's files to compare, and every file left out with its reason.

    Attributes:
        layout: The layout the download was read as ("canvas", "plain", ...).
        submissions: ``(identity, files)`` per student with at least one candidate file, sorted by identity.
        skipped: Files refused, not attributable, or of a student with nothing to compare (with reasons).
        names: Each file's own name as shown, where it is not ``path.name`` (a zip's entries are read into
            numbered files): ``grader.render.neutral.file_name`` of its place in the download. Only shown.
    """

    layout: str
    submissions: list[tuple[str, list[Path]]] = field(default_factory=list)
    skipped: list[UnreadableFile] = field(default_factory=list)
    names: dict[Path, str] = field(default_factory=dict)

    @property
    def identities(self) -> list[str]:
        """Every compared student's identity, sorted."""
        return [identity for identity, _ in self.submissions]


def submissions_from(
    path: Path,
    *,
    layout: str | None = None,
    sections: int | None = None,
    scratch: Path | None = None,
    rule: GradedFileRule | None = None,
) -> ClassSources:
    """The documents of a class download, read by grader/classroom/ as `gymgrade grade` reads it.

    Args:
        path: The download: a folder, a zip as the LMS gave it, or one file.
        layout: A ``grader.classroom.LAYOUTS`` name (``--layout``); recognised from the download when None.
        sections: Plain folders: levels of section folders (``--sections``); None: from the download's
            shape.
        scratch: Where zips are extracted (the caller removes it after the report is written); zips are
            listed as refused when None.
        rule: How the graded file (compared first) is chosen; by default as `gymgrade grade` chooses it
            with the bundled configuration (every enabled problem's function).

    Raises:
        ClassDirectoryError: When ``path`` does not exist.
        grader.classroom.errors.ClassroomError: When ``layout`` is unknown or the download is not of it.
    """
    if not path.exists() and not path.is_symlink():
        raise ClassDirectoryError(
            f"expected a class folder or zip (as the learning platform gave it), found {_what(path)} at {path}; "  # noqa: E501
            "pass the folder the submissions were downloaded into"
        )
    if rule is None:
        from grader.grading.plan import GradingPlan

        rule = GradedFileRule(functions=GradingPlan.load(None, None).problems)
    try:
        download = discover(path, layout=layout, sections=sections, rule=rule, scratch=scratch)
    except FileNotFoundError as error:
        raise ClassDirectoryError(str(error)) from None
    return sources_of(download)


def sources_of(download: ClassDownload) -> ClassSources:
    """The documents of an already discovered class download (``gymgrade grade --similarity`` reuses the
    batch's): each student's candidate files, the graded one first; the rest listed with a reason."""
    from grader.render.neutral import file_name

    sources = ClassSources(layout=download.layout)
    claimed: set[str] = set()
    for submission in download.submissions:
        mine = submission.refused
        claimed.update(skipped.where for skipped in mine)
        sources.skipped += _refused_listed(submission.identity, mine)
        candidates = [file for file in submission.files if is_candidate(file.original_name)]
        if submission.graded_file is not None and submission.graded_file in candidates:
            candidates.remove(submission.graded_file)
            candidates.insert(0, submission.graded_file)
        if candidates:
            sources.submissions.append((submission.identity, [file.path for file in candidates]))
            sources.names.update((file.path, file_name(file.relative)) for file in candidates)
            continue
        sources.skipped += [
            UnreadableFile(
                identity=submission.identity, file=file.relative, reason=_not_candidate(file.relative)
            )
            for file in submission.files
        ]
        if not submission.files and not mine:
            sources.skipped.append(
                UnreadableFile(
                    identity=submission.identity,
                    file=submission.identity,
                    reason=f"nothing to compare: {submission.why}.",
                )
            )
    sources.skipped += _refused_listed(
        REFUSED, [skipped for skipped in download.refused if skipped.where not in claimed]
    )
    sources.skipped += [
        UnreadableFile(
            identity=UNATTRIBUTED,
            file=skipped.where,
            reason=f"not attributed to a student: {skipped.reason}.",
        )
        for skipped in download.unattributed
    ]
    return sources


def _refused_listed(identity: str, refused: Sequence[Skipped]) -> list[UnreadableFile]:
    """The refused files of one student (or of nobody) as listed: the first ``MAX_REFUSED_LISTED``, then
    one line counting the rest (a zip of 80,000 links is one student's 21 lines)."""
    listed = [
        UnreadableFile(identity=identity, file=skipped.where, reason=f"refused: {skipped.reason}.")
        for skipped in refused[:MAX_REFUSED_LISTED]
    ]
    if len(refused) > MAX_REFUSED_LISTED:
        more = len(refused) - MAX_REFUSED_LISTED
        listed.append(
            UnreadableFile(
                identity=identity,
                file=f"{more:,} more refused files",
                reason="refused like those above; `gymgrade grade` on the download lists each of them.",
            )
        )
    return listed


def _not_candidate(relative: str) -> str:
    name = relative.rsplit("/", 1)[-1]
    if Path(name).suffix.lower() not in SOURCE_SUFFIXES:
        return f"{name} is neither a .py nor an .ipynb file: only Python sources and notebooks are compared."
    return f"{name} is a test, checkpoint or setup file, not a solution: not compared."


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


def read_source(path: Path, name: str = "") -> SourceText | Unreadable:
    """Read one submitted file as Python text, bounded in size, never executing or importing it, never
    following a link; a notebook's code cells come from the bounded reader (`grader.submission.notebook`).
    ``name`` is the file's own name as its messages show it (``path.name`` when empty); its kind follows
    ``path``."""
    result = _read_source(path, name or path.name)
    return replace(result, name=name) if name else result


def _read_source(path: Path, shown: str) -> SourceText | Unreadable:
    if path.is_dir() and not path.is_symlink():
        return Unreadable(path, f"{shown} holds no .py or .ipynb file: nothing to compare.")
    if not _has_source_suffix(path):
        return Unreadable(
            path,
            f"{shown} is neither a .py nor an .ipynb file: only Python sources and notebooks are compared.",
        )
    notebook = path.suffix.lower() == ".ipynb"
    limit = MAX_NOTEBOOK_BYTES if notebook else MAX_COMPARED_BYTES
    try:
        data = read_untrusted(path, limit=limit)
    except UnsafeFile as error:
        return Unreadable(path, f"{error} Left out.")
    if len(data) > limit:
        return Unreadable(
            path, f"{shown} is larger than {limit:,} bytes: too large to be a lab solution, left out."
        )
    if not data.strip():
        return Unreadable(path, f"{shown} is empty: nothing to compare.")
    if b"\0" in data:
        return Unreadable(path, f"{shown} is binary (it contains NUL bytes), not Python text: left out.")
    if notebook:  # read (its UTF-8 too) by the bounded reader: the parent never decodes it whole
        return _notebook_code(path, data, shown)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        return Unreadable(
            path, f"{shown} is not UTF-8 text (byte {error.start} cannot be decoded): left out."
        )
    return SourceText(path, text)


def _notebook_code(path: Path, data: bytes, shown: str) -> SourceText | Unreadable:
    read = read_notebook(data, shown)
    if isinstance(read, FileVerdict):
        return Unreadable(path, f"left out: {read.message}")
    chunks: list[str] = []
    notes: list[str] = []
    for cell in read.cells:
        lines = [_without_magic(line) for line in cell.source.splitlines()]
        if not _parses("\n".join(lines)):
            # one broken cell (a half-typed line) must not hide the rest of the notebook
            notes.append(f"{shown}: cell {cell.number} is not valid Python and was not compared.")
            lines = [""] * len(lines)
        chunks.append("\n".join(lines))
    code = "\n\n".join(chunks)
    if len(code.encode()) > MAX_COMPARED_BYTES:
        return Unreadable(
            path,
            f"{shown}'s code cells hold more than {MAX_COMPARED_BYTES:,} bytes: too large, left out.",
        )
    if not code.strip():
        return Unreadable(path, f"{shown} has no code cells: nothing to compare.")
    return SourceText(path, code + "\n", tuple(notes))


def _parses(code: str) -> bool:
    try:
        parsing.parse(code)
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
