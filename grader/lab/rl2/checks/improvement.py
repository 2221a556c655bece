"""The second lab's problem 2: `extract_policy(P, nS, nA, v, beta=1.0)` (2018-2023) or
`policy_improvement(P, nS, nA, V, beta=1.0)` (2024 on) returns the greedy policy for the values it is given.

Called on every MDP and discount of `mdp_calls.cases(seed)` twice: with the exact optimal values, and with
values drawn uniformly from [-1, 1] (drawn from the problem's seed and the case's key: another grading seed
asks other values), positionally.
A returned policy is right when, in every state, its action's one-step look-ahead
`sum p * (r + beta * v[s'])` is the best there up to `ROUNDING` (`reference.oracles.mdp.greedy_gaps`): any of
several tied actions is (FrozenLake's optimal actions tie in many states, the example's state 2 too), never
equality with one list. A wrong policy is compared with the typical mistakes, each named when it explains
every wrong policy.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from grader.lab.checks.base import CallRecord, Verdict, outcome_verdict, paused_gc
from grader.lab.rl2.checks.mdp_calls import (
    ROUNDING,
    FloatArray,
    IntArray,
    as_policy,
    call_text,
    called_case,
    cases,
    describe_values,
    first_outcomes,
    last_outcomes,
    mdp_call,
    optimum,
    shown,
)
from grader.lab.settings import ProblemConfig
from grader.sandbox.outcome import Call, FunctionInfo, PlainValue
from reference.oracles.mdp import Mdp, greedy_gaps, q_values
from reference.oracles.mdps import GradingCase, seeded_draw


class ImprovementConfig(ProblemConfig):
    """The settings of `extract_policy` / `policy_improvement(P, nS, nA, V, beta)` (no own fields)."""


@dataclass(frozen=True)
class Point:
    """One graded call: an MDP at a discount, and the values the policy is extracted from."""

    case: GradingCase
    values: FloatArray
    kind: str


OPTIMAL_VALUES, RANDOM_VALUES = "the optimal values", "random values"
BETA_AT, VALUES_AT = 4, 3
"""Where beta and V are in a call's arguments `(P, nS, nA, V, beta)`."""


def points(seed: int) -> tuple[Point, ...]:
    """The optimal values and random values (drawn from `seed`) of every case of the seed."""
    graded = []
    for case in cases(seed):
        graded.append(Point(case, optimum(case), OPTIMAL_VALUES))
        draw = seeded_draw(seed, f"values {case.key}")
        graded.append(Point(case, draw.uniform(-1.0, 1.0, case.mdp.n_states), RANDOM_VALUES))
    return tuple(graded)


def asked(call: Call) -> Point:
    """What a planned call asked: its MDP, discount and values, read from the call."""
    case = called_case(call, BETA_AT)
    values = np.asarray(call.args[VALUES_AT], dtype=np.float64)
    kind = OPTIMAL_VALUES if np.array_equal(values, optimum(case)) else RANDOM_VALUES
    return Point(case, values, kind)


def greedy_for(mdp: Mdp, values: FloatArray, beta: float, policy: IntArray) -> bool:
    """Whether `policy` takes a best one-step look-ahead action on `values` in every state."""
    gaps = greedy_gaps(mdp, values, policy, beta)
    scale = 1.0 + float(np.max(np.abs(q_values(mdp, values, beta))))
    return bool(np.all(gaps <= ROUNDING * scale))


MISTAKES: tuple[tuple[str, str], ...] = (
    (
        "beta",
        "beta ignored: your actions are greedy for discount 1 (the discount never applied); weigh the next state's value by beta: p * (r + beta * V[s'])",  # noqa: E501
    ),
    (
        "first",
        "first outcome only: your actions are greedy for P[s][a][0] alone; every outcome (p, s', r, done) in P[s][a] counts, weighted by p",  # noqa: E501
    ),
    (
        "last",
        "`=` where `+=` is meant: your actions are greedy for the last outcome of each move alone; add the outcomes up with +=",  # noqa: E501
    ),
)


def _explained(kind: str, point: Point, policy: IntArray) -> bool:
    mdp, beta = point.case.mdp, point.case.beta
    if kind == "beta":
        return greedy_for(mdp, point.values, 1.0, policy)
    if kind == "first":
        return greedy_for(first_outcomes(mdp), point.values, beta, policy)
    return greedy_for(last_outcomes(mdp), point.values, beta, policy)


@dataclass(frozen=True)
class ImprovementCheck:
    """Two calls per graded MDP; each policy judged by its look-ahead, ties allowed."""

    function: str

    def plan(
        self, settings: ImprovementConfig, functions: Mapping[str, FunctionInfo], seed: int
    ) -> list[Call]:
        """`function(P, nS, nA, V, beta)` for every point of the seed, positionally (V a fresh array)."""
        return [
            mdp_call(self.function, point.case, point.values.copy(), point.case.beta)
            for point in points(seed)
        ]

    @paused_gc
    def judge(self, settings: ImprovementConfig, records: Sequence[CallRecord]) -> Verdict:
        """Every policy greedy for its values; the mistake that explains every wrong one named."""
        early = outcome_verdict(records)
        if early is not None:
            return early
        graded = [(asked(record.outcome.call), record) for record in records]
        wrong: list[tuple[Point, Call, PlainValue, IntArray | None]] = []
        for point, record in graded:
            policy = as_policy(record.outcome.value, point.case.mdp)
            if policy is None or not greedy_for(point.case.mdp, point.values, point.case.beta, policy):
                wrong.append((point, record.outcome.call, record.outcome.value, policy))
        measurements: dict[str, PlainValue] = {"calls_graded": len(graded), "policies_wrong": len(wrong)}
        if not wrong:
            return Verdict(
                "passed",
                1.0,
                f"{self.function}: a greedy action in every state (ties allowed) in all {len(graded)} calls ({len(graded) // 2} MDPs and discounts, optimal and random values).",  # noqa: E501
                measurements,
            )
        return Verdict("failed", 0.0, self._problem(wrong, len(graded)), measurements)

    def _problem(self, wrong: Sequence[tuple[Point, Call, PlainValue, IntArray | None]], total: int) -> str:
        point, call, value, policy = wrong[0]
        mdp = point.case.mdp
        if policy is None:
            return f"{call_text(call)} returned {shown(value)}; expected a policy: one action number in 0..{mdp.n_actions - 1} for each of the {mdp.n_states} states of {mdp.name} ({len(wrong)} of {total} calls)."  # noqa: E501
        gaps = greedy_gaps(mdp, point.values, policy, point.case.beta)
        state = int(np.argmax(gaps))
        message = f"{call_text(call)} (V: {point.kind}) returned {describe_values(policy, 8)}; in state {state} its action {int(policy[state])} falls {gaps[state]:.4g} short of the best one-step look-ahead sum p * (r + beta * V[s']) at beta = {point.case.beta:g} ({len(wrong)} of {total} calls wrong)."  # noqa: E501
        usable = [(p, pol) for p, _, _, pol in wrong if pol is not None]
        if len(usable) == len(wrong):
            for kind, cause in MISTAKES:
                if all(_explained(kind, p, pol) for p, pol in usable):
                    return f"{message} Likely cause: {cause}."
        return message
