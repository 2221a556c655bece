"""The second lab's problem 3: `compute_policy_v(P, nS, nA, policy, beta=1.0, tol=1e-8)` (2018-2023) or
`iter_policy_eval(...)` (2024 on) returns ONE array: the policy's values by iterative evaluation.

Called on every MDP and discount of `mdp_calls.cases(seed)` with three policies: an optimal one, the lab's
all-ones start of policy iteration and a uniformly random one (drawn from the problem's seed and the case's
key), each whose value
is finite (at discount 1 a policy looping forever through costly moves has none and is not asked),
positionally `(P, nS, nA, policy, beta, tol)`. The values must lie within `mdp_calls.value_tolerance` of the
policy's exact value (`reference.oracles.mdp.policy_value`, a linear solve), the lab's own iterative
evaluation's error at that tol measured by the oracle at discount 1. `(V, n)` where one array is asked for
fails, named. A wrong V is compared with the typical mistakes, each named when it explains every wrong V.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from pydantic import Field

from grader.lab.checks.base import CallRecord, Verdict, outcome_verdict, paused_gc
from grader.lab.rl2.checks.mdp_calls import (
    CACHED,
    READINGS,
    FloatArray,
    IntArray,
    Reading,
    as_vector,
    bellman_sweep,
    call_text,
    called_case,
    cases,
    close,
    describe_values,
    first_outcomes,
    iterate,
    last_outcomes,
    mdp_call,
    shown,
    value_tolerance,
)
from grader.lab.settings import ProblemConfig
from grader.sandbox.outcome import Call, FunctionInfo, PlainValue
from reference.errors import UnboundedValueError
from reference.oracles.mdp import Mdp, optimal_solution, policy_value
from reference.oracles.mdps import GradingCase, seeded_draw

MAX_SWEEPS = 100_000
"""Sweeps the tolerance's measurement makes at most (the graded policies need at most about 1 200 at 1e-8)."""


class EvaluationConfig(ProblemConfig):
    """The settings of `compute_policy_v` / `iter_policy_eval(P, nS, nA, policy, beta, tol)`."""

    tol: float = Field(default=1e-8, gt=0.0, le=1e-4, description="The tol passed (the lab's default 1e-8).")


@dataclass(frozen=True)
class Point:
    """One graded call: an MDP at a discount, a policy with a finite value, that value and its tolerance."""

    case: GradingCase
    policy: IntArray
    kind: str
    exact: FloatArray


OPTIMAL, ALL_ONES, RANDOM = "an optimal policy", "the all-ones policy", "a random policy"
BETA_AT, POLICY_AT = 4, 3
"""Where beta and the policy are in a call's arguments `(P, nS, nA, policy, beta, tol)`."""


def policies(case: GradingCase, seed: int) -> list[tuple[str, IntArray]]:
    """The policies asked of a case: an optimal one, all ones, a random one drawn from `seed`."""
    draw = seeded_draw(seed, f"policy {case.key}")
    size = case.mdp.n_states
    return [
        (OPTIMAL, optimal_solution(case.mdp, case.beta).policy),
        (ALL_ONES, np.ones(size, dtype=np.int64)),
        (RANDOM, draw.integers(0, case.mdp.n_actions, size).astype(np.int64)),
    ]


@lru_cache(maxsize=CACHED)
def points(seed: int) -> tuple[Point, ...]:
    """Every (case, policy) of the seed whose value is finite, in case order."""
    graded = []
    for case in cases(seed):
        for kind, policy in policies(case, seed):
            try:
                exact = policy_value(case.mdp, policy, case.beta)
            except UnboundedValueError:
                continue
            graded.append(Point(case, policy, kind, exact))
    return tuple(graded)


def asked(call: Call) -> Point:
    """What a planned call asked: its MDP, discount and policy (with its exact value), read from the call."""
    case = called_case(call, BETA_AT)
    policy = np.asarray(call.args[POLICY_AT], dtype=np.int64)
    if np.array_equal(policy, optimal_solution(case.mdp, case.beta).policy):
        kind = OPTIMAL
    else:
        kind = ALL_ONES if bool(np.all(policy == 1)) else RANDOM
    return Point(case, policy, kind, policy_value(case.mdp, policy, case.beta))


def evaluation_tolerance(case: GradingCase, policy: IntArray, exact: FloatArray, tol: float) -> float:
    """How far an iterative evaluation of `policy` stopped at `tol` may lie from its exact value."""
    return _tolerance(case, tuple(int(action) for action in policy), tuple(exact.tolist()), tol)


@lru_cache(maxsize=CACHED)
def _tolerance(case: GradingCase, policy: tuple[int, ...], exact: tuple[float, ...], tol: float) -> float:
    actions = np.array(policy, dtype=np.int64)
    sweep = bellman_sweep(case.mdp, case.beta, actions)
    target = np.array(exact)
    worst = max(
        float(np.max(np.abs(iterate(sweep, case.mdp.n_states, tol, MAX_SWEEPS, reading)[0] - target)))
        for reading in READINGS
        if reading.norm == "max"  # the smallest norm, so the loosest stop
    )
    return value_tolerance(case, tol, worst, target)


def _evaluated(mdp: Mdp, beta: float, policy: IntArray, tol: float, start: float = 0.0) -> FloatArray:
    return _evaluation(mdp, beta, tuple(int(action) for action in policy), tol, start)


@lru_cache(maxsize=CACHED)
def _evaluation(mdp: Mdp, beta: float, policy: tuple[int, ...], tol: float, start: float) -> FloatArray:
    """The lab's iterative evaluation (from the previous V, max-norm stop) from V = `start`: what a mistake
    gives, memoised per case and policy (shared: read only)."""
    sweep = bellman_sweep(mdp, beta, np.array(policy, dtype=np.int64))
    start_values = np.full(mdp.n_states, start)
    values = iterate(sweep, mdp.n_states, tol, MAX_SWEEPS, Reading(False, "max"), start_values)[0]
    values.setflags(write=False)
    return values


def _undiscounted(point: Point, tol: float) -> FloatArray | None:
    """The policy's values at discount 1, or None where it has none (its evaluation never stops there)."""
    try:
        policy_value(point.case.mdp, point.policy, 1.0)
    except UnboundedValueError:
        return None
    return _evaluated(point.case.mdp, 1.0, point.policy, tol)


Mistake = Callable[[Point, float], FloatArray | None]

MISTAKES: tuple[tuple[str, Mistake], ...] = (
    (
        "beta ignored: your values are the policy's at discount 1 (the discount never applied); multiply the next state's value by beta",  # noqa: E501
        _undiscounted,
    ),
    (
        "first outcome only: your values read P[s][policy[s]][0] alone; every outcome in P[s][a] counts, weighted by its probability",  # noqa: E501
        lambda point, tol: _evaluated(first_outcomes(point.case.mdp), point.case.beta, point.policy, tol),
    ),
    (
        "`=` where `+=` is meant: your values are those of the last outcome of each move alone; add the outcomes up with +=",  # noqa: E501
        lambda point, tol: _evaluated(last_outcomes(point.case.mdp), point.case.beta, point.policy, tol),
    ),
    (
        "values initialised to ones: your evaluation starts from V = 1, which a terminal state looping to itself never clears at discount 1; start from zeros",  # noqa: E501
        lambda point, tol: _evaluated(point.case.mdp, point.case.beta, point.policy, tol, 1.0),
    ),
)


@dataclass(frozen=True)
class EvaluationCheck:
    """One call per graded (MDP, policy); one array, the policy's exact value within tolerance."""

    function: str

    def plan(
        self, settings: EvaluationConfig, functions: Mapping[str, FunctionInfo], seed: int
    ) -> list[Call]:
        """`function(P, nS, nA, policy, beta, tol)` for every point of the seed, positionally (the policy an int array)."""  # noqa: E501
        return [
            mdp_call(self.function, point.case, point.policy.copy(), point.case.beta, settings.tol)
            for point in points(seed)
        ]

    @paused_gc
    def judge(self, settings: EvaluationConfig, records: Sequence[CallRecord]) -> Verdict:
        """Each returned array against the policy's exact value; a tuple or a mistake named."""
        early = outcome_verdict(records)
        if early is not None:
            return early
        graded = [(asked(record.outcome.call), record) for record in records]
        tuples: list[Call] = []
        shapes: list[str] = []
        wrong: list[tuple[Point, Call, FloatArray, float]] = []
        for point, record in graded:
            value, call, size = record.outcome.value, record.outcome.call, point.case.mdp.n_states
            values = as_vector(value, size)
            if values is None:
                if isinstance(value, list) and len(value) >= 2 and as_vector(value[0], size) is not None:
                    tuples.append(call)
                else:
                    shapes.append(
                        f"{call_text(call)} returned {shown(value)}; expected one array of the {size} values"
                    )
                continue
            tolerance = evaluation_tolerance(point.case, point.policy, point.exact, settings.tol)
            if np.max(np.abs(values - point.exact)) > tolerance:
                wrong.append((point, call, values, tolerance))
        measurements: dict[str, PlainValue] = {
            "calls_graded": len(graded),
            "tuples_returned": len(tuples),
            "shapes_wrong": len(shapes),
            "values_wrong": len(wrong),
            "tol": settings.tol,
        }
        if tuples:
            return Verdict(
                "failed",
                0.0,
                f"{call_text(tuples[0])} returned a tuple where one array is asked for ({len(tuples)} of {len(graded)} calls): the lab's {self.function} returns the values alone, not (V, n); return V only (policy iteration uses the result as the values).",  # noqa: E501
                measurements,
            )
        if shapes:
            return Verdict(
                "failed", 0.0, f"{shapes[0]} ({len(shapes)} of {len(graded)} calls).", measurements
            )
        if not wrong:
            return Verdict(
                "passed",
                1.0,
                f"{self.function}: the policy's exact value within the tolerance tol = {settings.tol:g} earns, in all {len(graded)} calls (an optimal, the all-ones and a random policy on each MDP).",  # noqa: E501
                measurements,
            )
        return Verdict("failed", 0.0, _values_problem(wrong, len(graded), settings.tol), measurements)


def _values_problem(wrong: Sequence[tuple[Point, Call, FloatArray, float]], total: int, tol: float) -> str:
    point, call, values, tolerance = wrong[0]
    state = int(np.argmax(np.abs(values - point.exact)))
    message = f"{call_text(call)} ({point.kind}) returned {describe_values(values)}; its exact value on {point.case.mdp.name} at beta = {point.case.beta:g} is {describe_values(point.exact)} (state {state}: {values[state]:.6g} against {point.exact[state]:.6g}; tolerance {tolerance:.1e} at tol = {tol:g}). {len(wrong)} of {total} calls wrong."  # noqa: E501
    for cause, mistake in MISTAKES:
        if _explains(mistake, wrong, tol):
            return f"{message} Likely cause: {cause}."
    return message


def _explains(mistake: Mistake, wrong: Sequence[tuple[Point, Call, FloatArray, float]], tol: float) -> bool:
    """Whether the mistake gives every wrong value (where it gives one: a discount-1 evaluation of a policy
    with no value there never returns), and gives some."""
    explained = 0
    for point, _, values, _ in wrong:
        guess = mistake(point, tol)
        if guess is not None:
            if not close(values, guess):
                return False
            explained += 1
    return explained > 0
