"""One submission (or one reference file) as the comparison keeps it: fingerprints, remarks, constants.

A file is indexed on its own (`index_file`, the unit the reference cache stores); a document joins its
files, numbering lines as in `document_lines`, and drops what the lab's template provides.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from pydantic import BaseModel

from grader.classroom.similarity.normalise import normalise
from grader.classroom.similarity.sources import SourceText, Unreadable, read_source
from grader.classroom.similarity.template import Template
from grader.classroom.similarity.typos import misspellings
from grader.classroom.similarity.winnow import fingerprints

FILE_HEADER = "# ==== {name} ===="
"""Line written before each file when a document joins several (reports cite lines of the joined text)."""


class IndexedFile(BaseModel):
    """What one file contributes, serialisable (the reference cache stores exactly this).

    Attributes:
        lines: Number of lines of the file's text.
        shapes: Each unit's shape digest (template matching).
        unit_names: Each unit's name.
        fingerprints: ``[hash, unit, first line, last line]`` of every winnowed k-gram.
        remarks: ``[key, text, line]`` of every comment and longer string literal.
        constants: ``[value, line]`` of every numeric literal.
        truncated: True when the file was cut at the token limit.
        reason: Why the file could not be indexed (then everything else is empty).
    """

    lines: int = 0
    shapes: list[str] = []
    unit_names: list[str] = []
    fingerprints: list[tuple[int, int, int, int]] = []
    remarks: list[tuple[str, str, int]] = []
    constants: list[tuple[str, int]] = []
    truncated: bool = False
    reason: str | None = None


def index_text(text: str, name: str) -> IndexedFile:
    """Index a file's Python text; a file that is not Python gets its reason, never an exception."""
    lines = len(text.splitlines())
    try:
        normalised = normalise(text)
    except SyntaxError as error:
        where = f" (line {error.lineno})" if error.lineno else ""
        return IndexedFile(
            lines=lines, reason=f"{name} is not valid Python{where}: {error.msg}; left out of the comparison."
        )
    except RecursionError:
        return IndexedFile(
            lines=lines, reason=f"{name} nests too deeply to analyse; left out of the comparison."
        )
    return IndexedFile(
        lines=lines,
        shapes=[unit.shape for unit in normalised.units],
        unit_names=[unit.name for unit in normalised.units],
        fingerprints=[(f.hash, f.unit, f.first_line, f.last_line) for f in fingerprints(normalised.units)],
        remarks=[(remark.key, remark.text, remark.line) for remark in normalised.remarks],
        constants=normalised.constants,
        truncated=normalised.truncated,
    )


@dataclass
class Document:
    """A student's submission or a reference file, template removed, ready to compare.

    Attributes:
        identity: The student (as the class folder names them) or the reference file's path.
        is_reference: True for a --reference file.
        files: The files it was read from.
        fingerprints: Hash -> (unit, first line, last line) of its first k-gram (lines of the joined text).
        remarks: Remark key -> ``(text, line)``, first occurrence.
        constants: Numeric literal -> first line.
        typos: Known misspelling in a comment or string -> first line.
        template_functions: The functions dropped because they are the template's.
        notes: What the reader should know (a file cut, a notebook cell left out).
    """

    identity: str
    is_reference: bool
    files: list[Path]
    fingerprints: dict[int, tuple[int, int, int]] = field(default_factory=dict)
    remarks: dict[str, tuple[str, int]] = field(default_factory=dict)
    constants: dict[str, int] = field(default_factory=dict)
    typos: dict[str, int] = field(default_factory=dict)
    template_functions: set[str] = field(default_factory=set)
    notes: list[str] = field(default_factory=list)


def read_files(
    files: list[Path], names: Mapping[Path, str] | None = None
) -> tuple[list[SourceText], list[Unreadable]]:
    """The readable files' texts and the unreadable files' reasons, in the given order (``names``: each
    file's own name as shown, see ``ClassSources.names``)."""
    texts: list[SourceText] = []
    unreadable: list[Unreadable] = []
    for path in files:
        source = read_source(path, (names or {}).get(path, ""))
        (texts if isinstance(source, SourceText) else unreadable).append(source)  # type: ignore[arg-type]
    return texts, unreadable


def document_lines(texts: list[SourceText]) -> list[str]:
    """The lines reports cite: one file as it is, several joined, each after a ``FILE_HEADER`` line."""
    if len(texts) == 1:
        return texts[0].text.splitlines()
    lines: list[str] = []
    for source in texts:
        lines.append(FILE_HEADER.format(name=source.shown_name))
        lines.extend(source.text.splitlines())
    return lines


def build_document(
    identity: str,
    is_reference: bool,
    indexed: list[tuple[Path, IndexedFile]],
    template: Template,
    notes: Sequence[str] = (),
    names: Mapping[Path, str] | None = None,
) -> Document:
    """Join one submission's indexed files, dropping the template's functions, fingerprints and remarks."""
    document = Document(identity, is_reference, [path for path, _ in indexed])
    document.notes.extend(notes)
    offset = 1 if len(indexed) > 1 else 0
    unit_offset = 0
    for path, file in indexed:
        if file.reason is not None:
            offset += file.lines + (1 if len(indexed) > 1 else 0)
            continue
        if file.truncated:
            shown = (names or {}).get(path) or path.name
            document.notes.append(f"{shown} is very long: only its first part was compared.")
        kept_units = set()
        for number, (shape, name) in enumerate(zip(file.shapes, file.unit_names, strict=True)):
            if shape in template.shapes:
                document.template_functions.add(name)
            else:
                kept_units.add(number)
        for hash_, unit, first, last in file.fingerprints:
            if unit in kept_units and hash_ not in template.fingerprints:
                document.fingerprints.setdefault(hash_, (unit + unit_offset, first + offset, last + offset))
        for key, text, line in file.remarks:
            if key not in template.remarks:
                document.remarks.setdefault(key, (text, line + offset))
                for word in misspellings(key):
                    document.typos.setdefault(word, line + offset)
        for value, line in file.constants:
            document.constants.setdefault(value, line + offset)
        unit_offset += len(file.shapes)
        offset += file.lines + (1 if len(indexed) > 1 else 0)
    return document
