"""value_iteration's check: every branch fails a function of its own (judged here, no sandbox), the honest
readings pass, and each typical mistake is named."""

from __future__ import annotations

from functools import partial
from typing import Any

import numpy as np
import pytest

from grader.lab.rl2.checks.mdp_calls import cases
from grader.lab.rl2.checks.value_iteration import expected
from grader.sandbox.outcome import OutcomeStatus
from reference.rl2 import solutions
from tests.grader.lab.rl2.support import (
    SEED,
    judged,
    judged_outcomes,
    look_ahead,
    outcome,
    outcome_arrays,
    read_outcomes,
)


def value_iteration(
    P: Any,
    nS: int,
    nA: int,
    beta: float = 1.0,
    tol: float = 1e-8,
    maxiter: int = 3000,
    *,
    read: str = "all",
    discount: bool = True,
    start: float = 0.0,
    shift: int = 0,
    in_place: bool = False,
    norm: str = "l2",
    offset: float = 0.0,
) -> tuple[np.ndarray, int]:
    """The lab's value iteration, and each typical mistake as a switch.

    Each move's value adds `p * (r + beta * V[s'])` over its outcomes in their order, as the lab's loop over
    `P[s][a]` does: a sweep from the previous V on arrays of the outcomes (`support.look_ahead`), a sweep in
    place state by state on P's own lists.
    """
    factor = beta if discount else 1.0
    arrays = outcome_arrays(P, nS, nA, read)
    moves = [[read_outcomes(P[s][a], read) for a in range(nA)] for s in range(nS)]
    V = np.full(nS, start)
    for n in range(1, maxiter + 1):
        if in_place:
            values = V.tolist()
            for s in range(nS):
                q = [0.0] * nA
                for a in range(nA):
                    for p, s1, r, _ in moves[s][a]:
                        q[a] = q[a] + p * (r + factor * values[s1])
                values[s] = max(q)
            new = np.array(values)
        else:
            new = look_ahead(arrays, V, factor).max(axis=1)
        difference = new - V
        change = (
            np.max(np.abs(difference))
            if norm == "max"
            else np.sum(np.abs(difference))
            if norm == "l1"
            else np.linalg.norm(difference)
        )
        V = new
        if change < tol:
            return V + offset, n + shift
    return V + offset, maxiter


def test_the_reference_and_every_reading_the_text_allows_pass() -> None:
    for function in (
        solutions.value_iteration,
        value_iteration,
        partial(value_iteration, norm="max"),
        partial(value_iteration, in_place=True),
        partial(value_iteration, in_place=True, norm="max"),
    ):
        verdict = judged("v2024", "value_iteration", function)
        assert verdict.status == "passed", verdict.feedback
    assert "on all 12 MDPs" in verdict.feedback


def test_the_examples_count_is_the_labs_n_3_and_the_tolerance_derives_from_tol() -> None:
    example, discounted = cases(SEED)[0], cases(SEED)[1]
    assert expected(example, 1e-8, 3000).counts == (3,)
    assert expected(discounted, 1e-8, 3000).tolerance == pytest.approx(0.9 * 1e-8 / 0.1 + 2e-9)


@pytest.mark.parametrize(
    ("changes", "cause", "fraction"),
    [
        ({"discount": False}, "beta ignored", 0.0),
        ({"read": "first"}, "first outcome only", 0.0),
        ({"read": "last"}, "`=` where `+=` is meant", 0.0),
        ({"start": 1.0}, "values initialised to ones", 0.0),
        ({"shift": -1}, "counting the sweeps that changed V instead of the sweeps made (n - 1)", 0.75),
        ({"shift": 1}, "one sweep counted after the last one made (n + 1)", 0.75),
    ],
    ids=["beta-ignored", "first-outcome", "assigns", "ones", "counts-changes", "one-more"],
)
def test_each_typical_mistake_is_named(changes: dict[str, Any], cause: str, fraction: float) -> None:
    verdict = judged("v2024", "value_iteration", partial(value_iteration, **changes))
    assert (verdict.status, verdict.fraction) == ("failed", fraction)
    assert f"Likely cause: {cause}" in verdict.feedback
    if changes.get("shift") == -1:
        assert "on its example V1 = [0, 1, 1, 0], V2 = [1, 1, 1, 0], V3 = V2, so n = 3." in verdict.feedback


@pytest.mark.parametrize(
    ("function", "found"),
    [
        (partial(value_iteration, offset=0.5), "returned V = [1.5, 1.5, 1.5, 0.5]"),
        (
            lambda *args: (value_iteration(*args)[0], 7),
            "returned n = 7; the lab's value iteration from V = 0 makes 3 sweeps",
        ),
        (
            lambda *args: value_iteration(*args)[0],
            "returned an array of shape (4,) and dtype float64; expected (V, n)",
        ),
        (
            lambda *args: (list(value_iteration(*args)[0])[:-1], 3),
            "returned (V, n) with V a sequence of 3 items and n an int",
        ),
        (lambda *args: (value_iteration(*args)[0], 3.5), "expected (V, n)"),
    ],
    ids=["off-by-a-constant", "another-n", "V-alone", "V-too-short", "n-not-whole"],
)
def test_a_wrong_answer_no_mistake_explains_fails_without_a_cause(function: Any, found: str) -> None:
    verdict = judged("v2024", "value_iteration", function)
    assert verdict.status == "failed" and found in verdict.feedback, verdict.feedback
    assert "Likely cause" not in verdict.feedback


def test_hard_coding_the_examples_answers_fails_on_the_graders_own_mdps() -> None:
    def hard_coded(P: Any, nS: int, nA: int, beta: float = 1.0, *rest: Any) -> Any:
        return (np.array([1.0, 1.0, 1.0, 0.0]) if beta == 1 else np.array([beta, 1.0, 1.0, 0.0])), 3

    verdict = judged("v2024", "value_iteration", hard_coded)
    assert verdict.status == "failed"
    assert "FrozenLake 4x4 (slippery)" in verdict.feedback


def test_a_call_that_did_not_return_is_the_outcomes_verdict() -> None:
    verdict = judged_outcomes(
        "v2024",
        "value_iteration",
        lambda call: outcome(
            call, status=OutcomeStatus.TIMEOUT, message="value_iteration() did not return within 30 seconds"
        ),
    )
    assert verdict.status == "timeout" and "did not return within 30 seconds" in verdict.feedback


def test_the_2018_to_2022_texts_also_allow_counting_the_sweeps_that_changed_V() -> None:
    counts_changes = partial(value_iteration, shift=-1)
    for edition in ("v2018", "v2019"):
        verdict = judged(edition, "value_iteration", counts_changes)
        assert verdict.status == "passed", verdict.feedback
    verdict = judged("v2019", "value_iteration", partial(value_iteration, shift=-2))
    assert verdict.status == "failed" and "makes 2 or 3 sweeps there" in verdict.feedback
    for edition in ("v2023", "v2024", "v2026"):
        assert judged(edition, "value_iteration", counts_changes).status == "failed"


def test_a_1_norm_stop_is_a_reading_the_text_allows() -> None:
    verdict = judged("v2024", "value_iteration", partial(value_iteration, norm="l1"))
    assert verdict.status == "passed", verdict.feedback
