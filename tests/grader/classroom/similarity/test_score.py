"""Pair counting and scoring: the numpy inverted index counts exactly what a direct count finds."""

from __future__ import annotations

import random
from itertools import combinations

import pytest

from grader.classroom.similarity import score
from grader.classroom.similarity.document import Document
from grader.classroom.similarity.score import MIN_DENOMINATOR, candidate_pairs, fragments, pair_score


def _documents(seed: int) -> list[Document]:
    rng = random.Random(seed)
    documents = []
    for number in range(40):
        hashes = rng.sample(range(60), rng.randrange(0, 25))
        document = Document(f"d{number}", is_reference=number % 3 == 0, files=[])
        document.fingerprints = {hash_: (0, hash_, hash_) for hash_ in hashes}
        documents.append(document)
    return documents


@pytest.mark.parametrize("flush", [3, 1_000_000], ids=["merged in many batches", "merged once"])
def test_the_index_counts_every_shared_fingerprint_of_every_pair_but_reference_pairs(
    flush: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(score, "FLUSH_PAIRS", flush)
    documents = _documents(flush)
    common = frozenset({0, 1, 2})
    expected = {}
    for (first, a), (second, b) in combinations(enumerate(documents), 2):
        shared = len((a.fingerprints.keys() & b.fingerprints.keys()) - common)
        if shared and not (a.is_reference and b.is_reference):
            expected[(first, second)] = shared
    assert candidate_pairs(documents, common) == expected


def test_the_score_is_the_share_of_the_smaller_document_floored() -> None:
    assert pair_score(30, 30, 500) == 1.0
    assert pair_score(12, 40, 40) == 0.3
    assert pair_score(6, 6, 6) == round(6 / MIN_DENOMINATOR, 4)


def test_adjacent_matches_in_the_same_functions_form_one_fragment() -> None:
    a, b = Document("a", False, []), Document("b", False, [])
    a.fingerprints = {1: (0, 10, 11), 2: (0, 12, 13), 3: (1, 40, 41)}
    b.fingerprints = {1: (5, 20, 21), 2: (5, 22, 23), 3: (2, 70, 71)}
    found = fragments(a, b, frozenset())
    assert [(f.a_first, f.a_last, f.b_first, f.b_last) for f in found] == [(10, 13, 20, 23), (40, 41, 70, 71)]
