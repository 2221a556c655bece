"""Pair scoring: shared rare fingerprints, the fragments they form, and the bar a pair must pass to be shown.

``score = shared / max(min(|A|, |B|), MIN_DENOMINATOR)`` over fingerprints that are neither the template's
nor common: the share of the smaller document found in the other (a student who copied one function of
a long reference scores as high as one who copied it all), floored so that two tiny documents do not
score 1.0 on a few lines.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from itertools import combinations

from grader.similarity.document import Document
from grader.similarity.report import Fragment

SCORE_BAR = 0.3
MIN_SHARED = 8
"""A flagged pair shares at least this many fingerprints: about two short statements' worth of k-grams."""
MIN_DENOMINATOR = 24
MERGE_GAP = 2
"""Matched k-grams at most this many lines apart, in both documents, belong to one fragment."""


def candidate_pairs(documents: Sequence[Document], common: frozenset[int]) -> Counter[tuple[int, int]]:
    """How many rare fingerprints each pair of documents (not two references) shares: an inverted index."""
    postings: dict[int, list[int]] = {}
    for number, document in enumerate(documents):
        for hash_ in document.fingerprints:
            if hash_ not in common:
                postings.setdefault(hash_, []).append(number)
    shared: Counter[tuple[int, int]] = Counter()
    for holders in postings.values():
        if len(holders) < 2:
            continue
        for first, second in combinations(holders, 2):
            if not (documents[first].is_reference and documents[second].is_reference):
                shared[(first, second)] += 1
    return shared


def size(document: Document, common: frozenset[int]) -> int:
    """The number of rare fingerprints a document holds."""
    return sum(1 for hash_ in document.fingerprints if hash_ not in common)


def pair_score(shared: int, size_a: int, size_b: int) -> float:
    """The score of a pair sharing ``shared`` fingerprints (module docstring)."""
    return round(min(1.0, shared / max(min(size_a, size_b), MIN_DENOMINATOR)), 4)


def fragments(a: Document, b: Document, common: frozenset[int]) -> list[Fragment]:
    """The stretches of code two documents share, each from runs of matched k-grams in the same functions."""
    matches = sorted(
        (a.fingerprints[hash_][0], b.fingerprints[hash_][0])
        for hash_ in a.fingerprints.keys() & b.fingerprints.keys()
        if hash_ not in common
    )
    found: list[tuple[int, int, Fragment]] = []
    for (unit_a, a_first, a_last), (unit_b, b_first, b_last) in matches:
        if found:
            last_unit_a, last_unit_b, last = found[-1]
            if (
                unit_a == last_unit_a
                and unit_b == last_unit_b
                and a_first <= last.a_last + MERGE_GAP
                and last.b_first - MERGE_GAP <= b_first <= last.b_last + MERGE_GAP
            ):
                found[-1] = (
                    unit_a,
                    unit_b,
                    Fragment(
                        a_first=last.a_first,
                        a_last=max(last.a_last, a_last),
                        b_first=min(last.b_first, b_first),
                        b_last=max(last.b_last, b_last),
                    ),
                )
                continue
        found.append(
            (unit_a, unit_b, Fragment(a_first=a_first, a_last=a_last, b_first=b_first, b_last=b_last))
        )
    return [fragment for _, _, fragment in found]
