"""Synthetic reports and class entries for the class report's tests, built through the report models."""

from __future__ import annotations

from grader.classroom.report import ClassEntry
from grader.report import ProblemResult, Report, Status

TITLES = {"blackjack": "Problem 2", "cartpole": "Problem 3", "taxi": "Problem 5", "find_qvalues": "Q-values"}

STOOD_ON_N = (
    "blackjack({n}) returned {rate}; a player drawing on sums <= {n} wins 0.4170 of games "
    "(4080..4260 of 10000). Your games stood on a sum of exactly {n} in {hands} hands, so they follow "
    "'draw while the sum is < {n}': check `<` versus `<=`."
)
OFF_BY_ONE = (
    "blackjack({n}) returned {rate}; a player drawing on sums <= {n} wins 0.4170 of games "
    "(4080..4260 of 10000). Your games drew on a sum of {m} in {hands} hands, so they follow "
    "'draw while the sum is <= {m}': "
    "the threshold is off by one."
)
SHORT_POLE = (
    "cartpole(): your mean episode length is {mean} steps over {episodes} episodes; the lab asks for 195."
)


def result(problem: str, status: Status, feedback: str = "ok", *, points: float = 1.0) -> ProblemResult:
    """One problem's result: full points when passed (or skipped and worth nothing), else 0."""
    score = points if status == "passed" else 0.0
    return ProblemResult(
        id=problem, title=TITLES[problem], status=status, score=score, max_score=points, feedback=feedback
    )


def report(*results: ProblemResult, submission_error: str | None = None) -> Report:
    """A report holding ``results``, its score their sum."""
    return Report(
        submission="opengym.py",
        sha256="ab" * 32,
        seed=7,
        gymnasium_version="1.4.0",
        grader_version="0.1.0",
        score=sum(problem.score for problem in results),
        max_score=sum(problem.max_score for problem in results),
        submission_error=submission_error,
        problems=list(results),
    )


def graded(identity: str, *results: ProblemResult, late: bool = False, name: str | None = None) -> ClassEntry:
    """A graded student whose report holds ``results``, linked to ``<identity>.json``."""
    return ClassEntry(
        identity=identity, name=name, report=report(*results), late=late, report_href=f"{identity}.json"
    )


def all_passed(identity: str, **kwargs: bool) -> ClassEntry:
    """A student who passed blackjack, cartpole and taxi."""
    return graded(
        identity, *(result(problem, "passed") for problem in ("blackjack", "cartpole", "taxi")), **kwargs
    )
