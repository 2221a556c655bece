"""The improvement step's check (extract_policy to 2023, policy_improvement since 2024): any greedy action
passes, ties included; each typical mistake fails and is named."""

from __future__ import annotations

from functools import partial
from typing import Any

import numpy as np
import pytest

from reference.rl2 import solutions
from tests.grader.lab.rl2.support import judged


def improvement(
    P: Any,
    nS: int,
    nA: int,
    V: Any,
    beta: float = 1.0,
    *,
    read: str = "all",
    discount: bool = True,
    last_tie: bool = False,
) -> np.ndarray:
    factor = beta if discount else 1.0
    q = np.zeros((nS, nA))
    for s in range(nS):
        for a in range(nA):
            outcomes = P[s][a][:1] if read == "first" else P[s][a]
            for p, s1, r, _ in outcomes:
                term = p * (r + factor * V[s1])
                q[s, a] = term if read == "last" else q[s, a] + term
    if last_tie:  # the last of the best actions: another tie-break, as right as the first
        return nA - 1 - np.argmax(q[:, ::-1], axis=1)
    return np.argmax(q, axis=1)


@pytest.mark.parametrize(
    ("edition", "problem"), [("v2018", "extract_policy"), ("v2024", "policy_improvement")]
)
def test_the_reference_passes_under_each_editions_name(edition: str, problem: str) -> None:
    verdict = judged(edition, problem, solutions.policy_improvement)
    assert verdict.status == "passed", verdict.feedback
    assert "in all 24 calls" in verdict.feedback


def test_another_tie_break_is_as_right() -> None:
    verdict = judged("v2024", "policy_improvement", partial(improvement, last_tie=True))
    assert verdict.status == "passed", verdict.feedback


@pytest.mark.parametrize(
    ("changes", "cause"),
    [
        ({"discount": False}, "beta ignored"),
        ({"read": "first"}, "first outcome only"),
        ({"read": "last"}, "`=` where `+=` is meant"),
    ],
    ids=["beta-ignored", "first-outcome", "assigns"],
)
def test_each_typical_mistake_is_named(changes: dict[str, Any], cause: str) -> None:
    verdict = judged("v2024", "policy_improvement", partial(improvement, **changes))
    assert verdict.status == "failed" and f"Likely cause: {cause}" in verdict.feedback, verdict.feedback
    assert "falls" in verdict.feedback and "short of the best one-step look-ahead" in verdict.feedback


@pytest.mark.parametrize(
    ("function", "found"),
    [
        (lambda *args: np.zeros(len(args[0]), dtype=int), "short of the best one-step look-ahead"),
        (
            lambda *args: [2, 1, 2, 0],
            "of 24 calls",  # the example's answer, 4 actions where 16 are asked, or not greedy
        ),
        (lambda *args: improvement(*args) + 0.5, "expected a policy"),
        (lambda *args: improvement(*args) + 4, "expected a policy"),
        (lambda *args: (improvement(*args), 1), "returned a sequence of 2 items"),
    ],
    ids=["all-zeros", "the-examples-answer", "not-whole", "out-of-range", "tuple"],
)
def test_a_wrong_policy_fails_without_a_cause(function: Any, found: str) -> None:
    verdict = judged("v2024", "policy_improvement", function)
    assert verdict.status == "failed" and found in verdict.feedback, verdict.feedback
    assert "Likely cause" not in verdict.feedback
