"""Pair scoring: shared rare fingerprints, the fragments they form, and the bar a pair must pass to be shown.

``score = shared / max(min(|A|, |B|), MIN_DENOMINATOR)`` over fingerprints that are neither the template's
nor common: the share of the smaller document found in the other (a student who copied one function of
a long reference scores as high as one who copied it all), floored so that two tiny documents do not
score 1.0 on a few lines.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from grader.classroom.similarity.document import Document
from grader.classroom.similarity.report import Fragment

SCORE_BAR = 0.3
MIN_SHARED = 8
"""A flagged pair shares at least this many fingerprints: about two short statements' worth of k-grams."""
MIN_DENOMINATOR = 24
MERGE_GAP = 2
"""Matched k-grams at most this many lines apart, in both documents, belong to one fragment."""


def candidate_pairs(documents: Sequence[Document], common: frozenset[int]) -> dict[tuple[int, int], int]:
    """How many rare fingerprints each pair of documents shares (never two references), by an inverted index.

    A pair is keyed by its two indexes in increasing order. Pairs are counted as
    integer codes in numpy, a batch at a time: a fingerprint held by h documents adds up to h^2/2 pairs,
    and h may reach the frequency filter's limit (a tenth of the class plus a tenth of the references).
    """
    count = len(documents)
    postings: dict[int, list[int]] = {}
    for number, document in enumerate(documents):
        for hash_ in document.fingerprints:
            if hash_ not in common:
                postings.setdefault(hash_, []).append(number)
    is_reference = np.array([document.is_reference for document in documents], dtype=bool)
    codes: list[np.ndarray] = []
    pending = 0
    totals = (np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64))
    for holders in postings.values():
        if len(holders) < 2:
            continue
        members = np.array(holders, dtype=np.int64)
        students = members[~is_reference[members]]
        if students.size == 0:
            continue
        others = members[None, :]
        keep = (others > students[:, None]) | is_reference[others]
        pair_codes = (students[:, None] * count + others)[keep]
        codes.append(pair_codes)
        pending += pair_codes.size
        if pending > FLUSH_PAIRS:
            totals = _merged(totals, codes)
            codes, pending = [], 0
    totals = _merged(totals, codes)
    pairs: dict[tuple[int, int], int] = {}
    for code, shared in zip(totals[0].tolist(), totals[1].tolist(), strict=True):
        first, second = divmod(code, count)
        pairs[(first, second) if first < second else (second, first)] = shared
    return pairs


FLUSH_PAIRS = 1_000_000
"""Pair codes held before they are merged into the counts: bounds memory by the pairs, not the sum of h^2."""


def _merged(totals: tuple[np.ndarray, np.ndarray], codes: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    if not codes:
        return totals
    unique, counts = np.unique(np.concatenate(codes), return_counts=True)
    if totals[0].size == 0:
        return unique, counts
    merged_codes = np.concatenate([totals[0], unique])
    merged_counts = np.concatenate([totals[1], counts])
    order_codes, inverse = np.unique(merged_codes, return_inverse=True)
    return order_codes, np.bincount(inverse, weights=merged_counts).astype(np.int64)


def size(document: Document, common: frozenset[int]) -> int:
    """The number of rare fingerprints a document holds."""
    return sum(1 for hash_ in document.fingerprints if hash_ not in common)


def pair_score(shared: int, size_a: int, size_b: int) -> float:
    """The score of a pair sharing ``shared`` fingerprints (module docstring)."""
    return round(min(1.0, shared / max(min(size_a, size_b), MIN_DENOMINATOR)), 4)


def fragments(a: Document, b: Document, common: frozenset[int]) -> list[Fragment]:
    """The stretches of code two documents share, each from runs of matched k-grams in the same functions."""
    matches = sorted(
        (a.fingerprints[hash_], b.fingerprints[hash_])
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
