"""The similarity check's shell: find the files, read and index them (references cached), compare."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from grader.classroom.similarity.behaviour import WrongResults
from grader.classroom.similarity.cache import IndexCache
from grader.classroom.similarity.compare import build_report
from grader.classroom.similarity.document import (
    Document,
    IndexedFile,
    build_document,
    document_lines,
    index_text,
    read_files,
)
from grader.classroom.similarity.report import SimilarityReport, UnreadableFile
from grader.classroom.similarity.sources import (
    MAX_FILES_PER_SUBMISSION,
    ClassSources,
    SourceText,
    Unreadable,
    references_from,
    submissions_from,
)
from grader.classroom.similarity.template import Template, load_template


@dataclass(frozen=True)
class Outcome:
    """A finished comparison: the report, and each compared identity's files (for the side-by-side view).

    Attributes:
        report: The report.
        files: Identity -> its files, for every student and reference.
    """

    report: SimilarityReport
    files: dict[str, list[Path]]
    names: dict[Path, str] = field(default_factory=dict)
    """Each file's own name as shown, where it is not ``path.name`` (``ClassSources.names``)."""

    def lines_of(self, identity: str) -> list[str]:
        """The compared text of one identity, line by line, as the report's line numbers count them."""
        texts, _ = read_files(self.files.get(identity, []), self.names)
        return document_lines(texts)


def run_similarity(
    class_dir: Path | ClassSources,
    references: Sequence[Path] = (),
    *,
    template: Template | None = None,
    cache: IndexCache | None = None,
    behaviour: dict[str, WrongResults] | None = None,
    notes: Sequence[str] = (),
    workers: int | None = None,
) -> Outcome:
    """Compare a class with itself and with reference folders.

    Args:
        class_dir: The class download (a plain folder here; zips and a ``--layout`` need
            ``submissions_from(path, layout=..., scratch=...)`` first), or its documents already found.
        references: Folders of known solutions; every file in them is a document.
        template: What to remove (the bundled lab templates by default).
        cache: Where reference indexes are kept between runs (none: index every time).
        behaviour: Wrong results by student identity, from grading reports.
        notes: Extra notes for the report.
        workers: Processes that index files (default: one per core; 1 indexes in this process).

    Raises:
        ClassDirectoryError: When a folder does not exist.
    """
    template = template or load_template()
    sources = class_dir if isinstance(class_dir, ClassSources) else submissions_from(class_dir)
    names = sources.names
    unreadable: list[UnreadableFile] = list(sources.skipped)
    jobs: list[tuple[str, bool, list[Path]]] = []
    for identity, paths in sources.submissions:
        unreadable.extend(
            UnreadableFile(
                identity=identity,
                file=names.get(extra) or extra.name,
                reason=f"{identity} has more than {MAX_FILES_PER_SUBMISSION} Python files: {names.get(extra) or extra.name} was not read.",  # noqa: E501
            )
            for extra in paths[MAX_FILES_PER_SUBMISSION:]
        )
        jobs.append((identity, False, paths[:MAX_FILES_PER_SUBMISSION]))
    jobs.extend(
        (identity, True, [path]) for folder in references for identity, path in references_from(folder)
    )
    workers = workers or os.cpu_count() or 1
    documents: list[Document] = []
    files: dict[str, list[Path]] = {}
    pool = ProcessPoolExecutor(workers) if workers > 1 and len(jobs) > BATCH else None
    try:
        for start in range(0, len(jobs), BATCH):
            batch = jobs[start : start + BATCH]
            for (identity, _, paths), document in zip(
                batch, _documents(batch, template, cache, unreadable, pool, workers, names), strict=True
            ):
                if document is not None:
                    documents.append(document)
                    files[identity] = paths
    finally:
        if pool is not None:
            pool.shutdown()
    cache_notes = cache.notes if cache is not None else []
    report = build_report(documents, unreadable, behaviour, template.names, [*notes, *cache_notes])
    return Outcome(report, files, names)


BATCH = 64
"""Documents read and indexed together: only one batch's texts are in memory at a time."""


def _documents(
    jobs: list[tuple[str, bool, list[Path]]],
    template: Template,
    cache: IndexCache | None,
    unreadable: list[UnreadableFile],
    pool: ProcessPoolExecutor | None,
    readers: int,
    names: Mapping[Path, str],
) -> list[Document | None]:
    """Read a batch of documents (``readers`` at a time), index the files not cached (in the pool, if
    any), and build them."""
    texts: list[list[SourceText]] = []
    indexed: dict[tuple[int, int], IndexedFile] = {}
    missing: list[tuple[int, int, SourceText]] = []
    # A notebook is read by a bounded child process (grader.submission.notebook): `readers` threads wait for
    # those children, one document each.
    with ThreadPoolExecutor(readers) as threads:
        reads = list(threads.map(lambda paths: read_files(paths, names), [paths for _, _, paths in jobs]))
    for number, ((identity, is_reference, _), (readable, failures)) in enumerate(
        zip(jobs, reads, strict=True)
    ):
        unreadable.extend(_listed(identity, failure) for failure in failures)
        texts.append(readable)
        for position, source in enumerate(readable):
            entry = cache.get(source.text, identity) if cache is not None and is_reference else None
            if entry is None:
                missing.append((number, position, source))
            else:
                indexed[(number, position)] = entry
    arguments = ([source.text for _, _, source in missing], [source.shown_name for _, _, source in missing])
    results = (
        pool.map(index_text, *arguments, chunksize=4) if pool is not None else map(index_text, *arguments)
    )
    for (number, position, source), entry in zip(missing, results, strict=True):
        indexed[(number, position)] = entry
        if cache is not None and jobs[number][1]:
            cache.put(source.text, entry)
    documents: list[Document | None] = []
    for number, (identity, is_reference, _) in enumerate(jobs):
        entries = [
            (source.path, indexed[(number, position)]) for position, source in enumerate(texts[number])
        ]
        for path, entry in entries:
            if entry.reason is not None:
                shown = names.get(path) or path.name
                unreadable.append(UnreadableFile(identity=identity, file=shown, reason=entry.reason))
        if all(entry.reason is not None for _, entry in entries):
            documents.append(None)
        else:
            notes = [note for source in texts[number] for note in source.notes]
            documents.append(build_document(identity, is_reference, entries, template, notes, names))
    return documents


def _listed(identity: str, failure: Unreadable) -> UnreadableFile:
    return UnreadableFile(identity=identity, file=failure.shown_name, reason=failure.reason)
