"""The comparison's pure core: documents in, a ranked `SimilarityReport` out (no files, no clock)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from itertools import combinations

from grader.classroom.similarity.behaviour import WrongResults, rare_wrong_results, shared_wrong_results
from grader.classroom.similarity.clusters import clusters
from grader.classroom.similarity.document import Document
from grader.classroom.similarity.evidence import shared_constants, shared_remarks, shared_typos
from grader.classroom.similarity.frequency import Frequencies, frequencies
from grader.classroom.similarity.report import Pair, SimilarityReport, UnreadableFile
from grader.classroom.similarity.score import (
    MIN_SHARED,
    SCORE_BAR,
    candidate_pairs,
    fragments,
    pair_score,
    size,
)

EVIDENCE_BAR = 3
"""Identical rare comments, unusual constants and wrong results: this many flag a pair whatever its code."""
MAX_FRAGMENTS = 12
"""Fragments kept per pair (the longest); the count says how many there were."""


def flagged_pairs(
    documents: Sequence[Document],
    behaviour: Mapping[str, WrongResults] | None = None,
) -> list[Pair]:
    """The pairs worth a person's reading, with their fragments and evidence, highest score first.

    A pair is flagged by its code (score >= ``SCORE_BAR`` on at least ``MIN_SHARED`` fingerprints) or by
    ``EVIDENCE_BAR`` pieces of evidence. Fragments and evidence are computed for those pairs only.

    Args:
        documents: Students and references, template already removed.
        behaviour: Wrong results by student identity (from grading reports), if any.
    """
    counts = frequencies(documents)
    behaviour = behaviour or {}
    rare_behaviour = rare_wrong_results(behaviour)
    sizes = [size(document, counts.common) for document in documents]
    shared = candidate_pairs(documents, counts.common)
    by_code = {
        pair
        for pair, count in shared.items()
        if count >= MIN_SHARED and pair_score(count, sizes[pair[0]], sizes[pair[1]]) >= SCORE_BAR
    }
    pairs: list[Pair] = []
    for first, second in sorted(by_code | _evidence_pairs(documents, counts, behaviour)):
        count = shared.get((first, second), 0)
        a, b = documents[first], documents[second]
        if a.is_reference:
            a, b = b, a
        evidence = shared_remarks(a, b, counts) + shared_typos(a, b, counts) + shared_constants(a, b, counts)
        evidence += shared_wrong_results(
            behaviour.get(a.identity, {}), behaviour.get(b.identity, {}), rare_behaviour
        )
        if (first, second) not in by_code and len(evidence) < EVIDENCE_BAR:
            continue
        found = fragments(a, b, counts.common)
        pairs.append(
            Pair(
                a=a.identity,
                b=b.identity,
                b_is_reference=b.is_reference,
                score=pair_score(count, sizes[first], sizes[second]),
                shared_fingerprints=count,
                shared_fragments=len(found),
                longest_fragment_lines=max((fragment.lines for fragment in found), default=0),
                evidence=evidence,
                fragments=sorted(found, key=lambda fragment: -fragment.lines)[:MAX_FRAGMENTS],
            )
        )
    return sorted(pairs, key=lambda pair: (-pair.score, -len(pair.evidence), pair.a, pair.b))


def all_scores(documents: Sequence[Document]) -> dict[frozenset[str], float]:
    """The score of every pair sharing at least one rare fingerprint (for ranking studies and tests)."""
    common = frequencies(documents).common
    sizes = [size(document, common) for document in documents]
    return {
        frozenset((documents[first].identity, documents[second].identity)): pair_score(
            count, sizes[first], sizes[second]
        )
        for (first, second), count in candidate_pairs(documents, common).items()
    }


def build_report(
    documents: Sequence[Document],
    unreadable: Sequence[UnreadableFile] = (),
    behaviour: Mapping[str, WrongResults] | None = None,
    template_functions: Sequence[str] = (),
    notes: Sequence[str] = (),
) -> SimilarityReport:
    """The report of a class: its flagged pairs ranked, their clusters, and every file left out."""
    flagged = flagged_pairs(documents, behaviour)
    students = [document.identity for document in documents if not document.is_reference]
    all_notes = list(notes)
    if not students:
        all_notes.append("no readable submission was found in the class folder: nothing was compared.")
    all_notes.extend(f"{document.identity}: {note}" for document in documents for note in document.notes)
    return SimilarityReport(
        students=students,
        references=sum(1 for document in documents if document.is_reference),
        pairs=flagged,
        clusters=clusters((pair.a, pair.b) for pair in flagged),
        unreadable=list(unreadable),
        notes=all_notes,
        template_functions=list(template_functions),
    )


def _evidence_pairs(
    documents: Sequence[Document], counts: Frequencies, behaviour: Mapping[str, WrongResults]
) -> set[tuple[int, int]]:
    """Pairs sharing a rare comment, constant or wrong result (each is held by at most two documents)."""
    holders: dict[str, list[int]] = {}
    rare_behaviour = rare_wrong_results(behaviour)
    for number, document in enumerate(documents):
        keys = [f"r:{key}" for key in document.remarks.keys() & counts.rare_remarks]
        keys += [f"c:{value}" for value in document.constants.keys() & counts.rare_constants]
        keys += [f"t:{word}" for word in document.typos.keys() & counts.rare_typos]
        keys += [f"b:{key}" for key in behaviour.get(document.identity, {}).keys() & rare_behaviour]
        for key in keys:
            holders.setdefault(key, []).append(number)
    found: set[tuple[int, int]] = set()
    for numbers in holders.values():
        for first, second in combinations(numbers, 2):
            if not (documents[first].is_reference and documents[second].is_reference):
                found.add((first, second))
    return found
