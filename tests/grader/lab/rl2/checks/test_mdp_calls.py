"""The second lab's pure problems plan from the problem's seed: the same seed plans the same calls, another
seed other MDPs and draws; a file that memorised the public cases' answers fails under any seed."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pytest

from grader.lab.checks.base import CallRecord
from grader.lab.editions import edition_of
from grader.lab.rl2.checks.mdp_calls import as_count, as_vector, call_text, called_case
from grader.lab.rl2.editions import PURE_2024
from grader.sandbox.outcome import Call, CallOutcome, MdpArgument, OutcomeStatus
from reference.rl2 import solutions
from tests.grader.lab.rl2.support import judged, judged_outcomes, outcome, settings, wire

ROOT = Path(__file__).resolve().parents[5]
MEMORISER = ROOT / "submissions" / "rl2" / "hostile" / "memorised_public_cases.py"
PURE = tuple(problem.id for problem in PURE_2024)
"""The 2024 edition's pure problems, in lab order."""


def _plan(problem: str, seed: int) -> list[Call]:
    return edition_of("v2024").registry.problem(problem).check.plan(settings("v2024", problem), {}, seed)


def _plain(call: Call) -> Any:
    """A call as comparable plain data (tables, arrays as lists)."""
    args = [
        (arg.name, arg.table)
        if isinstance(arg, MdpArgument)
        else arg.tolist()
        if isinstance(arg, np.ndarray)
        else arg
        for arg in call.args
    ]
    return (call.function, args, call.provided)


@pytest.mark.parametrize("problem", PURE)
def test_the_same_seed_plans_the_same_calls_and_another_seed_other_mdps(problem: str) -> None:
    assert [_plain(c) for c in _plan(problem, 11)] == [_plain(c) for c in _plan(problem, 11)]
    first, second = (
        [c for c in _plan(problem, seed) if c.args[0].name.startswith("a random MDP")] for seed in (11, 12)
    )
    assert len(first) == len(second) >= 3
    assert all(a.args[0].table != b.args[0].table for a, b in zip(first, second, strict=True))


@pytest.mark.parametrize("problem", ["policy_improvement", "iter_policy_eval"])
def test_the_random_inputs_of_the_public_cases_follow_the_seed(problem: str) -> None:
    def asked(seed: int) -> set[tuple[str, float, tuple[float, ...]]]:
        return {
            (c.args[0].name, float(c.args[4]), tuple(np.asarray(c.args[3], dtype=float).tolist()))
            for c in _plan(problem, seed)
            if not c.args[0].name.startswith("a random MDP")
        }

    # the random values or policy of each public case (10) changes with the seed, bar an equal draw or
    # a random policy with no value at discount 1 (not asked)
    assert len(asked(11) - asked(12)) >= 8


def test_the_judge_reads_each_calls_mdp_from_the_call() -> None:
    for call in _plan("value_iteration", 3):
        case = called_case(call, 3)
        assert case.mdp.table == call.args[0].table and case.beta == call.args[3]


def _memoriser() -> ModuleType:
    spec = importlib.util.spec_from_file_location("memorised_public_cases", MEMORISER)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("seed", [0, 1, 20261128])
@pytest.mark.parametrize("problem", PURE)
def test_a_file_that_memorised_the_public_cases_fails_under_a_grading_seed(problem: str, seed: int) -> None:
    verdict = judged("v2024", problem, getattr(_memoriser(), problem), seed=seed)
    assert verdict.status == "failed", verdict.feedback


@pytest.mark.parametrize("problem", ["value_iteration", "policy_iteration"])
def test_the_memoriser_is_right_on_every_public_case(problem: str) -> None:
    """It would pass a plan of the public cases alone: it is the threat the held-out MDPs answer."""
    entry = edition_of("v2024").registry.problem(problem)
    chosen = settings("v2024", problem)
    function = getattr(_memoriser(), problem)
    records = []
    for call in entry.check.plan(chosen, {}, 0):
        if call.args[0].name.startswith("a random MDP"):
            continue
        args = [arg.as_table() if isinstance(arg, MdpArgument) else arg for arg in call.args]
        records.append(CallRecord(outcome(call, wire(function(*args))), []))
    verdict = entry.check.judge(chosen, records)
    assert verdict.status == "passed", verdict.feedback


def test_values_as_a_list_and_a_whole_float_count_are_read_as_the_lab_returns_them() -> None:
    """`V.tolist()` and `float(n)` are the same answer: a list of numbers is the values, 3.0 is 3 sweeps."""

    def listed(P: Any, nS: int, nA: int, beta: float = 1.0, tol: float = 1e-8, maxiter: int = 3000) -> Any:
        values, sweeps = solutions.value_iteration(P, nS, nA, beta, tol, maxiter)
        return [float(v) for v in values], float(sweeps)

    verdict = judged("v2024", "value_iteration", listed)
    assert verdict.status == "passed", verdict.feedback


@pytest.mark.parametrize(
    ("value", "read"),
    [
        ([1, 2.5], [1.0, 2.5]),
        (np.array([[1], [2]]), [1.0, 2.0]),
        ([1, "2"], None),
        ([True, False], None),
        ([1.0, float("nan")], None),
        ([1.0], None),
        ((1.0, 2.0), None),
    ],
    ids=["list", "column", "text-item", "bools", "nan", "too-short", "tuple"],
)
def test_a_returned_vector_is_numbers_only(value: Any, read: list[float] | None) -> None:
    vector = as_vector(value, 2)
    assert (None if vector is None else vector.tolist()) == read


@pytest.mark.parametrize(
    ("value", "count"),
    [(3, 3), (3.0, 3), (3.5, None), (float("inf"), None), (True, None), ("3", None)],
    ids=["int", "whole-float", "fraction", "inf", "bool", "text"],
)
def test_a_returned_count_is_an_int_or_a_whole_float(value: Any, count: int | None) -> None:
    assert as_count(value) == count


def test_feedback_shows_an_array_argument_by_its_size_and_the_table_by_its_name() -> None:
    call = next(c for c in _plan("iter_policy_eval", 0) if isinstance(c.args[3], np.ndarray))
    assert call_text(call) == (
        f"iter_policy_eval(<P of {call.args[0].name}>, {call.args[1]}, {call.args[2]}, "
        f"<array of {call.args[3].size}>, {call.args[4]!r}, {call.args[5]!r})"
    )


def test_a_planned_call_without_an_mdp_first_is_the_graders_error() -> None:
    call = Call("value_iteration", ([[0]], 1, 1, 0.9, 1e-8, 3000))
    with pytest.raises(TypeError, match="the first argument planned is not an MDP table"):
        called_case(call, 3)


@pytest.mark.parametrize("problem", PURE)
def test_a_call_that_raised_is_the_verdict_before_any_value_is_read(problem: str) -> None:
    def raised(call: Any) -> CallOutcome:
        return outcome(call, None, OutcomeStatus.EXCEPTION, "ZeroDivisionError: division by zero")

    verdict = judged_outcomes("v2024", problem, raised)
    assert verdict.status == "error" and "ZeroDivisionError" in verdict.feedback, verdict.feedback
