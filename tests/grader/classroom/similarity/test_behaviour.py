"""Shared wrong behaviour is evidence; identical correct behaviour, or a mistake many share, never is."""

from __future__ import annotations

from pathlib import Path

from grader.classroom.similarity.behaviour import (
    load_wrong_results,
    rare_wrong_results,
    shared_wrong_results,
    wrong_results,
)
from grader.classroom.similarity.compare import EVIDENCE_BAR, flagged_pairs
from grader.classroom.similarity.document import Document
from grader.report import ProblemResult, Report


def _report(name: str, *results: tuple[str, str, float], seed: int = 7) -> Report:
    problems = [
        ProblemResult(
            id=problem,
            title=problem.title(),
            status=status,  # type: ignore[arg-type]
            score=1.0 if status == "passed" else 0.0,
            max_score=1.0,
            feedback="",
            measurements={"win_rate": value},
        )
        for problem, status, value in results
    ]
    return Report(
        submission=name,
        sha256="0" * 64,
        seed=seed,
        gymnasium_version="1",
        grader_version="1",
        score=0.0,
        max_score=float(len(problems)),
        problems=problems,
    )


def test_only_failed_results_are_kept_and_equal_wrong_numbers_on_the_same_seed_match() -> None:
    a = wrong_results(_report("a", ("blackjack", "failed", 0.3712), ("cartpole", "passed", 195.0)))
    b = wrong_results(_report("b", ("blackjack", "failed", 0.3712), ("cartpole", "passed", 195.0)))
    other_seed = wrong_results(_report("c", ("blackjack", "failed", 0.3712), seed=8))
    assert len(a) == 1
    rare = rare_wrong_results({"a": a, "b": b, "c": other_seed})
    assert shared_wrong_results(a, b, rare) == [
        'the same wrong result on Blackjack from the same seed (7): {"win_rate": 0.3712}'
    ]
    assert shared_wrong_results(a, other_seed, rare) == []


def test_a_mistake_many_students_make_is_not_evidence() -> None:
    results = {name: wrong_results(_report(name, ("blackjack", "failed", 37.12))) for name in "abc"}
    assert shared_wrong_results(results["a"], results["b"], rare_wrong_results(results)) == []


def test_shared_wrong_results_flag_a_pair_whose_code_shares_nothing(tmp_path: Path) -> None:
    wrong = [("blackjack", "failed", 0.11), ("car", "failed", 201.0), ("taxi", "failed", -3.5)]
    for name in ("ana", "ben", "cid"):
        results = wrong if name != "cid" else [(problem, "passed", value) for problem, _, value in wrong]
        (tmp_path / f"{name}.json").write_text(_report(name, *results).to_json(), encoding="utf-8")
    (tmp_path / "dee.json").write_text("not json", encoding="utf-8")
    behaviour, notes = load_wrong_results(tmp_path, ["ana", "ben", "cid", "dee", "eve"])
    assert notes == ["dee.json: not a gymgrade report (ValidationError); its behaviour is not compared."]
    documents = [Document(name, False, []) for name in ("ana", "ben", "cid")]
    (pair,) = flagged_pairs(documents, behaviour)
    assert (pair.a, pair.b, pair.score) == ("ana", "ben", 0.0)
    assert len(pair.evidence) == EVIDENCE_BAR
