"""The similarity check's shell: find the files, read and index them (references through the cache), compare."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from grader.similarity.behaviour import WrongResults
from grader.similarity.cache import IndexCache
from grader.similarity.compare import build_report
from grader.similarity.document import Document, IndexedFile, build_document, document_lines, index_text, read_files
from grader.similarity.report import SimilarityReport, UnreadableFile
from grader.similarity.sources import MAX_FILES_PER_SUBMISSION, Unreadable, references_from, submissions_from
from grader.similarity.template import Template, load_template

Discovery = Callable[[Path], list[tuple[str, Path]]]


@dataclass(frozen=True)
class Outcome:
    """A finished comparison: the report, and where each compared identity's files are (for the side-by-side view).

    Attributes:
        report: The report.
        files: Identity -> its files, for every student and reference.
    """

    report: SimilarityReport
    files: dict[str, list[Path]]

    def lines_of(self, identity: str) -> list[str]:
        """The compared text of one identity, line by line, as the report's line numbers count them."""
        texts, _ = read_files(self.files.get(identity, []))
        return document_lines(texts)


def run_similarity(
    class_dir: Path,
    references: Sequence[Path] = (),
    *,
    template: Template | None = None,
    cache: IndexCache | None = None,
    behaviour: dict[str, WrongResults] | None = None,
    discover: Discovery = submissions_from,
    notes: Sequence[str] = (),
) -> Outcome:
    """Compare a class with itself and with reference folders.

    Args:
        class_dir: The class folder (`discover` reads its layout).
        references: Folders of known solutions; every file in them is a document.
        template: What to remove (the bundled lab templates by default).
        cache: Where reference indexes are kept between runs (none: index every time).
        behaviour: Wrong results by student identity, from grading reports.
        discover: The class layout reader.
        notes: Extra notes for the report.

    Raises:
        ClassDirectoryError: When a folder does not exist.
    """
    template = template or load_template()
    grouped: dict[str, list[Path]] = {}
    for identity, path in discover(class_dir):
        grouped.setdefault(identity, []).append(path)
    reference_files = [entry for folder in references for entry in references_from(folder)]
    documents: list[Document] = []
    unreadable: list[UnreadableFile] = []
    files: dict[str, list[Path]] = {}
    for identity, paths in grouped.items():
        for extra in paths[MAX_FILES_PER_SUBMISSION:]:
            unreadable.append(
                UnreadableFile(
                    identity=identity,
                    file=extra.name,
                    reason=f"{identity} has more than {MAX_FILES_PER_SUBMISSION} Python files: {extra.name} was not read.",
                )
            )
        document = _document(identity, False, paths[:MAX_FILES_PER_SUBMISSION], template, None, unreadable)
        if document is not None:
            documents.append(document)
            files[identity] = paths[:MAX_FILES_PER_SUBMISSION]
    for identity, path in reference_files:
        document = _document(identity, True, [path], template, cache, unreadable)
        if document is not None:
            documents.append(document)
            files[identity] = [path]
    report = build_report(documents, unreadable, behaviour, template.names, notes)
    return Outcome(report, files)


def _document(
    identity: str,
    is_reference: bool,
    paths: list[Path],
    template: Template,
    cache: IndexCache | None,
    unreadable: list[UnreadableFile],
) -> Document | None:
    texts, failures = read_files(paths)
    unreadable.extend(_listed(identity, failure) for failure in failures)
    indexed: list[tuple[Path, IndexedFile]] = []
    for source in texts:
        entry = cache.get(source.text) if cache is not None else None
        if entry is None:
            entry = index_text(source.text, source.path.name)
            if cache is not None:
                cache.put(source.text, entry)
        if entry.reason is not None:
            unreadable.append(UnreadableFile(identity=identity, file=source.path.name, reason=entry.reason))
        indexed.append((source.path, entry))
    if all(entry.reason is not None for _, entry in indexed):
        return None
    return build_document(identity, is_reference, indexed, template)


def _listed(identity: str, failure: Unreadable) -> UnreadableFile:
    return UnreadableFile(identity=identity, file=failure.path.name, reason=failure.reason)
