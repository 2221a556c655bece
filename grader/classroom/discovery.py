"""Recognising a class download and making one submission per student (or group) of it."""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

from grader.classroom.errors import LayoutMismatch, UnknownLayout
from grader.classroom.graded_file import GradedFileRule, choose
from grader.classroom.layouts import LAYOUTS, Group, Layout
from grader.classroom.layouts.plain import PlainLayout
from grader.classroom.model import ClassDownload, Member, Skipped, Submission, SubmittedFile
from grader.classroom.tree import Budget, Entry, Limits, Tree, read_tree

DEFAULT_RULE = GradedFileRule()
DEFAULT_LIMITS = Limits()
RECOGNISED = 0.5
"""Share of a download's top-level names that must carry an LMS's marks for it to be taken as that LMS's."""


def recognise(tree: Tree) -> Layout:
    """The layout whose marks the download carries most (plain folders when no LMS's reach RECOGNISED)."""
    scored = sorted(((layout.score(tree), name) for name, layout in LAYOUTS.items()), reverse=True)
    best_score, best = scored[0]
    return LAYOUTS[best] if best_score >= RECOGNISED else LAYOUTS["plain"]


def layout_named(name: str) -> Layout:
    """The layout of a ``--layout`` name.

    Raises:
        UnknownLayout: No layout has that name (the message lists them).
    """
    try:
        return LAYOUTS[name]
    except KeyError:
        raise UnknownLayout(f"unknown layout {name!r}: use one of {', '.join(LAYOUTS)}") from None


@dataclass(frozen=True)
class ReadDownload:
    """A download read once (zips extracted into scratch) and its layout, before files are grouped by a
    graded-file rule: `submissions_of` makes submissions of it as often as needed, reading nothing again."""

    path: Path
    layout: Layout
    tree: Tree
    named: bool = False


def read_download(
    path: Path,
    *,
    layout: str | None = None,
    sections: int | None = None,
    scratch: Path | None = None,
    limits: Limits = DEFAULT_LIMITS,
    budget: Budget | None = None,
) -> ReadDownload:
    """Read a class download and recognise its layout.

    Reads only under ``path`` (links are refused, never followed) and writes only into ``scratch``
    (zips, read within ``limits``, counted against ``budget`` when several downloads share one).

    Args:
        path: The download: a folder, a zip as the LMS gave it, or one file.
        layout: A ``LAYOUTS`` name; recognised from the download when None.
        sections: Plain folders only: how many levels of section folders hold the students' folders
            (None: decided from the download's shape as a whole).
        scratch: Folder zips are read into; zips are refused when None.
        limits: Bounds on files, bytes and zip nesting.
        budget: What other downloads of the same command used of ``limits`` (shared); a fresh one when None.

    Raises:
        FileNotFoundError: ``path`` does not exist.
        grader.classroom.errors.ClassroomError: ``layout`` is unknown, ``sections`` is given for another
            layout than plain folders.
    """
    if not path.exists() and not path.is_symlink():
        raise FileNotFoundError(f"{path} does not exist: pass the class folder or zip as downloaded")
    chosen = layout_named(layout) if layout else None
    if sections is not None:
        if chosen is not None and chosen.name != "plain":
            raise LayoutMismatch(
                f"--sections {sections} describes plain folders, but --layout {chosen.name} was given: "
                "leave out --sections (the LMS's layout names its students itself)"
            )
        chosen = PlainLayout(sections=sections)
    tree = read_tree(path, scratch, limits, budget)
    return ReadDownload(
        path, chosen or recognise(tree), tree, named=chosen is not None and layout is not None
    )


def submissions_of(
    read: ReadDownload, *, rule: GradedFileRule = DEFAULT_RULE, due: datetime | None = None
) -> ClassDownload:
    """Group a read download's files by student and choose each graded file by ``rule``.

    Raises:
        grader.classroom.errors.ClassroomError: A layout named with ``--layout`` does not fit.
    """
    chosen, tree, path = read.layout, read.tree, read.path
    if read.named and chosen.name != "plain" and tree.entries and chosen.score(tree) == 0:
        raise LayoutMismatch(
            f"{path} does not look like a {chosen.title} download (none of its names carry its marks); "
            f"leave out --layout to recognise it, or pass the download as {chosen.title} gives it"
        )
    grouping = chosen.group(tree)
    download = ClassDownload(
        layout=chosen.name,
        root=path,
        unattributed=grouping.unattributed,
        refused=tree.refused,
        ignored=tree.ignored,
    )
    refused_by = _refused_by_student(chosen, tree)
    for group in _merged(grouping.groups):
        refused = refused_by.pop(group.identity, (group.members, []))[1]
        download.submissions.append(_submission(group, rule, chosen.name, due, refused))
    for identity, (members, refused) in refused_by.items():
        download.submissions.append(
            Submission(
                identity=identity,
                display_name=_display(members, identity),
                members=members,
                files=(),
                graded_file=None,
                why=f"nothing to grade: every file was refused ({_refusals(refused)})",
                source=chosen.name,
                refused=tuple(refused),
            )
        )
    download.submissions.sort(key=lambda submission: submission.identity)
    return download


def discover(
    path: Path,
    *,
    layout: str | None = None,
    sections: int | None = None,
    rule: GradedFileRule = DEFAULT_RULE,
    scratch: Path | None = None,
    limits: Limits = DEFAULT_LIMITS,
    due: datetime | None = None,
) -> ClassDownload:
    """Read a class download: recognise its layout, group files by student, choose each graded file
    (`read_download`, then `submissions_of`).

    Args:
        path: The download: a folder, a zip as the LMS gave it, or one file.
        layout: A ``LAYOUTS`` name; recognised from the download when None.
        sections: Plain folders: levels of section folders (None: from the download's shape).
        rule: How the graded file is chosen.
        scratch: Folder zips are read into; zips are refused when None.
        limits: Bounds on files, bytes and zip nesting.
        due: The deadline; a submission whose source gives a time but no late mark is late after it.

    Returns:
        The submissions sorted by identity, with the unattributed and refused files.

    Raises:
        FileNotFoundError: ``path`` does not exist.
        grader.classroom.errors.ClassroomError: ``layout`` is unknown or the download is not of it.
    """
    read = read_download(path, layout=layout, sections=sections, scratch=scratch, limits=limits)
    return submissions_of(read, rule=rule, due=due)


def read_all(
    paths: Sequence[Path],
    *,
    layout: str | None = None,
    sections: int | None = None,
    scratch: Path | None = None,
    limits: Limits = DEFAULT_LIMITS,
) -> list[ReadDownload]:
    """`read_download` each path (zips into a scratch subfolder of their own), all within one budget of
    ``limits``: the bounds hold for everything one command reads."""
    budget = Budget()
    return [
        read_download(
            path,
            layout=layout,
            sections=sections,
            scratch=scratch / str(index) if scratch else None,
            limits=limits,
            budget=budget,
        )
        for index, path in enumerate(paths)
    ]


def submissions_of_all(
    reads: Sequence[ReadDownload], *, rule: GradedFileRule = DEFAULT_RULE, due: datetime | None = None
) -> ClassDownload:
    """`submissions_of` each read download, put together (``layout`` "mixed" when they differ). A student
    found under two paths keeps the first submission; the second is refused with a reason."""
    found = [submissions_of(read, rule=rule, due=due) for read in reads]
    if len(found) == 1:
        return found[0]
    layouts = {download.layout for download in found}
    merged = ClassDownload(layout=layouts.pop() if len(layouts) == 1 else "mixed", root=reads[0].path.parent)
    by_identity: dict[str, Submission] = {}
    for download in found:
        merged.unattributed += download.unattributed
        merged.refused += download.refused
        merged.ignored += download.ignored
        for submission in download.submissions:
            if submission.identity in by_identity:
                merged.refused.append(_duplicate(submission, by_identity[submission.identity]))
                continue
            by_identity[submission.identity] = submission
    merged.submissions = sorted(by_identity.values(), key=lambda submission: submission.identity)
    return merged


def discover_all(
    paths: Sequence[Path],
    *,
    layout: str | None = None,
    sections: int | None = None,
    rule: GradedFileRule = DEFAULT_RULE,
    scratch: Path | None = None,
    limits: Limits = DEFAULT_LIMITS,
    due: datetime | None = None,
) -> ClassDownload:
    """:func:`discover` several downloads into one class (`read_all`, one budget, then
    `submissions_of_all`)."""
    reads = read_all(paths, layout=layout, sections=sections, scratch=scratch, limits=limits)
    return submissions_of_all(reads, rule=rule, due=due)


def _duplicate(later: Submission, kept: Submission) -> Skipped:
    where = later.graded_file.relative if later.graded_file else later.identity
    return Skipped(
        where,
        f"a second submission for {later.identity} (kept {kept.graded_file.relative if kept.graded_file else 'the first'}); pass each student once",  # noqa: E501
    )


REFUSED_ENTRY = "(refused entry)"
"""The stand-in name of a refused zip entry whose own name climbs out or is absolute: it is attributed to
the folder or zip that holds it, never named for a student by its name (``../x`` is nobody's)."""
MAX_REFUSALS_NAMED = 5
"""Refused files a submission's ``why`` names; the rest are counted (``Submission.refused`` has them all)."""


def _holder(where: str) -> str | None:
    """Where a refused file is attributed from: ``where`` when it is a plain relative path, else a stand-in
    inside the folder or zip holding it (``alice/sub.zip/../x`` -> ``alice/sub.zip/(refused entry)``), or
    None when nothing holds it (``../x``, ``/tmp/x``, ``C:/x`` at the top of the download)."""
    parts = where.replace("\\", "/").split("/")
    for number, part in enumerate(parts):
        if part in ("", ".", "..") or "\x00" in part or (len(part) > 1 and part[1] == ":"):
            return "/".join([*parts[:number], REFUSED_ENTRY]) if number else None
    return where


def _regroup(layout: Layout, tree: Tree) -> tuple[list[Group], dict[str, list[Skipped]]]:
    """The groups of the download with its refused files put back as stand-ins (``os.devnull``: nothing of
    theirs is read), so that each refused file can be said to be some student's; and the refused files of
    each stand-in."""
    refused_at: dict[str, list[Skipped]] = {}
    for skipped in tree.refused:
        holder = _holder(skipped.where)
        if holder is not None:
            refused_at.setdefault(holder, []).append(skipped)
    stand_ins = [Entry(holder, Path(os.devnull)) for holder in refused_at]
    grouping = layout.group(
        Tree(root=tree.root, entries=sorted([*tree.entries, *stand_ins], key=lambda e: e.relative))
    )
    return grouping.groups, refused_at


def _refused_by_student(layout: Layout, tree: Tree) -> dict[str, tuple[tuple[Member, ...], list[Skipped]]]:
    """The refused files of each student a layout can name for them, with the student's members."""
    if not tree.refused:
        return {}
    groups, refused_at = _regroup(layout, tree)
    found: dict[str, tuple[tuple[Member, ...], list[Skipped]]] = {}
    for group in _merged(groups):
        mine = [
            skipped
            for entry, _ in group.files
            if entry.path == Path(os.devnull)
            for skipped in refused_at.get(entry.relative, ())
        ]
        if mine:
            found[group.identity] = (group.members, mine)
    return found


def _refusals(refused: list[Skipped]) -> str:
    named = "; ".join(f"{skipped.where}: {skipped.reason}" for skipped in refused[:MAX_REFUSALS_NAMED])
    more = len(refused) - MAX_REFUSALS_NAMED
    return f"{named}; and {more:,} more" if more > 0 else named


def _display(members: tuple[Member, ...], identity: str) -> str:
    names = ", ".join(member.name for member in members if member.name)
    return f"{names} ({identity})" if names else identity


def _merged(groups: list[Group]) -> list[Group]:
    """Groups of one identity (a student's folder and a file of their name) made one."""
    by_identity: dict[str, Group] = {}
    for group in groups:
        if group.identity in by_identity:
            by_identity[group.identity].files += group.files
        else:
            by_identity[group.identity] = group
    return list(by_identity.values())


def _submission(
    group: Group, rule: GradedFileRule, source: str, due: datetime | None, refused: list[Skipped]
) -> Submission:
    files = tuple(SubmittedFile(entry.path, entry.relative, original) for entry, original in group.files)
    graded, why = choose(files, rule)
    if refused:
        why = f"{why}; refused {_refusals(refused)}"
    late = group.late
    if late is None and due is not None and group.submitted_at is not None:
        late = _aware(group.submitted_at, due) > _aware(due, due)
    return Submission(
        identity=group.identity,
        display_name=_display(group.members, group.identity),
        members=group.members,
        files=files,
        graded_file=graded,
        why=f"{why}; {group.note}" if group.note else why,
        submitted_at=group.submitted_at,
        late=late,
        source=source,
        refused=tuple(refused),
    )


def _aware(moment: datetime, due: datetime) -> datetime:
    """A time a source gives without a zone (Blackboard's file names) is read in the due time's zone."""
    return moment if moment.tzinfo is not None else moment.replace(tzinfo=due.tzinfo or UTC)
