"""The corpus of submissions/similarity/ (written for this test): copied pairs rank above independent ones.

submissions/similarity/expected.toml lists the copied pairs (one per disguise, a reference copy, a ring of
three) and the template-only students; every other pair is independent.
"""

from __future__ import annotations

import tomllib
from itertools import combinations
from pathlib import Path

import pytest

from grader.classroom.similarity.compare import all_scores
from grader.classroom.similarity.document import Document
from grader.classroom.similarity.run import Outcome, run_similarity

CORPUS = Path(__file__).resolve().parents[4] / "submissions" / "similarity"
EXPECTED = tomllib.loads((CORPUS / "expected.toml").read_text(encoding="utf-8"))
COPIED = {name: frozenset(pair) for name, pair in EXPECTED["copied"].items()}
REFERENCES = sorted(path for path in (CORPUS / "references").iterdir() if path.is_dir())


@pytest.fixture(scope="module")
def documents() -> list[Document]:
    captured: list[Document] = []

    def capture(found: list[Document], *args: object, **kwargs: object) -> object:
        captured.extend(found)
        return build(found, *args, **kwargs)

    import grader.classroom.similarity.run as run_module

    build = run_module.build_report
    run_module.build_report = capture  # type: ignore[assignment]
    try:
        run_similarity(CORPUS / "class", REFERENCES)
    finally:
        run_module.build_report = build
    return captured


@pytest.fixture(scope="module")
def outcome() -> Outcome:
    return run_similarity(CORPUS / "class", REFERENCES)


def _scores(documents: list[Document]) -> dict[frozenset[str], float]:
    scored = all_scores(documents)
    return {
        frozenset((a.identity, b.identity)): scored.get(frozenset((a.identity, b.identity)), 0.0)
        for a, b in combinations(documents, 2)
        if not (a.is_reference and b.is_reference)
    }


def test_every_copied_pair_ranks_above_every_independent_pair(documents: list[Document]) -> None:
    scores = _scores(documents)
    copied = {pair: scores[pair] for pair in COPIED.values()}
    independent = {pair: score for pair, score in scores.items() if pair not in COPIED.values()}
    assert len(independent) > 200
    lowest_copied = min(copied, key=copied.__getitem__)
    highest_independent = max(independent, key=independent.__getitem__)
    assert copied[lowest_copied] > independent[highest_independent], (
        sorted(lowest_copied),
        sorted(highest_independent),
    )


@pytest.mark.parametrize("disguise", list(COPIED), ids=list(COPIED))
def test_each_disguise_is_flagged(outcome: Outcome, disguise: str) -> None:
    flagged = {frozenset((pair.a, pair.b)) for pair in outcome.report.pairs}
    assert COPIED[disguise] in flagged


def test_only_copied_pairs_are_flagged_so_no_template_only_or_independent_pair_is(outcome: Outcome) -> None:
    flagged = {frozenset((pair.a, pair.b)) for pair in outcome.report.pairs}
    assert flagged == set(COPIED.values())
    template_only = set(EXPECTED["groups"]["template_only"])
    assert not any(pair & template_only for pair in flagged)


def test_the_ring_is_one_cluster(outcome: Outcome) -> None:
    assert sorted(EXPECTED["groups"]["ring"]) in outcome.report.clusters
    assert all(len(cluster) == 2 for cluster in outcome.report.clusters if "ring_a" not in cluster)


def test_template_only_submissions_keep_nothing_of_the_template(documents: list[Document]) -> None:
    by_identity = {document.identity: document for document in documents}
    assert by_identity["t_template_only"].fingerprints == {}
    removed = {name: by_identity[name].template_functions for name in EXPECTED["groups"]["template_only"]}
    assert "qlearn" in removed["t_rl1_stub"] and "epsilon_decay" not in removed["t_rl1_stub"]
    assert "find_qvalues" in removed["t_cartpole_only"] and "cartpole" not in removed["t_cartpole_only"]


def test_a_reference_match_names_the_reference_file(outcome: Outcome) -> None:
    pair = next(pair for pair in outcome.report.pairs if pair.a == "omar_haddad")
    assert (pair.b, pair.b_is_reference) == ("public_2021/opengym_solution.py", True)
    assert pair.longest_fragment_lines >= 5


def test_the_report_lists_evidence_besides_code(outcome: Outcome) -> None:
    ring = next(pair for pair in outcome.report.pairs if {pair.a, pair.b} == {"ring_a", "ring_b"})
    assert any("recieve" in item for item in ring.evidence)


def test_a_shared_misspelling_is_evidence_once(outcome: Outcome) -> None:
    pair = next(pair for pair in outcome.report.pairs if {pair.a, pair.b} == {"ring_a", "ring_b"})
    assert [item for item in pair.evidence if "recieve" in item] == [
        'the same misspelling "recieve" (ring_a line 9, ring_b line 9)'
    ]
