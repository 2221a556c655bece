"""The second lab's problem 4: `policy_iteration(P, nS, nA, beta=1, tol=1e-8, maxiter=200)` returns
`(V, policy, n)`.

Called once on every MDP and discount of `mdp_calls.cases(seed)` with `(P, nS, nA, beta, tol, maxiter)`
positionally. The policy is judged by its exact value (`reference.oracles.mdp.judge_policy`: optimal in
every state, ties allowed, never equality with one list); V against the exact optimal values within the
tolerance an iterative evaluation of the returned policy earns at that tol
(`evaluation.evaluation_tolerance`); n must be a whole number from 1 to maxiter (the texts fix no
convention for it).

**Which evaluation and improvement.** The student's policy_iteration calls its evaluation and improvement
steps by name. With `helpers = "student_then_grader"` (the default) it is judged first as written, with the
submission's own; only when that verdict is not a pass is it judged again with the grader's own (the lab's
algorithms, `grader.sandbox.child.provided`) bound in their place for each call, and the better verdict is
kept (`grader.lab.checks.base.SecondReading`): a mistake in those steps counts in their own problems, and a
policy_iteration written for its own steps (one that unpacks its own `V, n = compute_policy_v(...)`, or
passes its own policy representation) is never judged against steps it was not written for. `"grader"`
binds the grader's in every call, `"student"` never. The feedback says which reading gave the verdict.

**A start that never converges.** Every MDP asked at discount 1 is the lab's own or lets every policy end
(`reference.oracles.mdps`), so every start the texts allow converges but one: on the lab's own example a
start policy that walks 0 -> 1 -> 0 (right, then left, at a cost of 1 a lap) has no finite value, and its
iterative evaluation never stops. The call reaches its time limit (`call_seconds`) and the problem is
`timeout`, named; the other problems are graded as usual.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydantic import Field

from grader.lab.checks.base import CallRecord, Verdict, better_reading, outcome_verdict, paused_gc
from grader.lab.rl2.checks.evaluation import evaluation_tolerance
from grader.lab.rl2.checks.mdp_calls import (
    as_count,
    as_policy,
    as_vector,
    call_text,
    called_case,
    cases,
    describe_values,
    mdp_call,
    optimum,
    shown,
)
from grader.lab.settings import ProblemConfig
from grader.sandbox.outcome import Call, FunctionInfo, OutcomeStatus, PlainValue
from reference.errors import UnboundedValueError
from reference.oracles.mdp import judge_policy, policy_value, trapping_states
from reference.oracles.mdps import GradingCase

FUNCTION = "policy_iteration"


class PolicyIterationConfig(ProblemConfig):
    """The settings of `policy_iteration(P, nS, nA, beta, tol, maxiter)`."""

    tol: float = Field(default=1e-8, gt=0.0, le=1e-4, description="The tol passed (the lab's default 1e-8).")
    maxiter: int = Field(
        default=200, ge=10, le=10_000, description="The maxiter passed (the lab's default 200)."
    )
    helpers: Literal["student_then_grader", "grader", "student"] = Field(
        default="student_then_grader",
        description="'student_then_grader': judged with the submission's own evaluation and improvement steps, then, only if that verdict is not a pass, again with the grader's own in their place, the better verdict kept; 'grader': the grader's own in every call; 'student': the submission's own only.",  # noqa: E501
    )


BETA_AT = 3
"""Where beta is in a call's arguments `(P, nS, nA, beta, tol, maxiter)`."""


@dataclass(frozen=True)
class PolicyIterationCheck:
    """One call per graded MDP; the policy judged by its exact value, V against the optimum. A
    `SecondReading`: judged again with the grader's steps when the student's own do not pass.

    Attributes:
        evaluation: The edition's name of the evaluation step (the grader's bound in the second reading).
        improvement: The edition's name of the improvement step.
    """

    evaluation: str
    improvement: str

    def plan(
        self, settings: PolicyIterationConfig, functions: Mapping[str, FunctionInfo], seed: int
    ) -> list[Call]:
        """`policy_iteration(P, nS, nA, beta, tol, maxiter)` on every case, positionally (the first reading:
        the grader's steps bound only with `helpers = "grader"`)."""
        return self._calls(settings, seed, provided=settings.helpers == "grader")

    def second_plan(
        self,
        settings: PolicyIterationConfig,
        first: Verdict,
        functions: Mapping[str, FunctionInfo],
        seed: int,
    ) -> list[Call]:
        """The same calls with the grader's evaluation and improvement steps bound, when the student's own
        reading did not pass (`helpers = "student_then_grader"`); else none."""
        if settings.helpers != "student_then_grader" or first.status == "passed":
            return []
        return self._calls(settings, seed, provided=True)

    def keep(self, settings: PolicyIterationConfig, first: Verdict, second: Verdict) -> Verdict:
        """The better of the two readings, the student's own on a tie."""
        return better_reading(first, second)

    def _calls(self, settings: PolicyIterationConfig, seed: int, *, provided: bool) -> list[Call]:
        names = (self.evaluation, self.improvement) if provided else ()
        calls = []
        for case in cases(seed):
            call = mdp_call(FUNCTION, case, case.beta, settings.tol, settings.maxiter)
            calls.append(
                Call(call.function, call.args, record_episodes=True, budget=call.budget, provided=names)
            )
        return calls

    def _reading(self, records: Sequence[CallRecord]) -> str:
        if any(record.outcome.call.provided for record in records):
            return f"policy_iteration was called with the grader's own {self.evaluation} and {self.improvement} (the lab's algorithms) in place of yours, so a mistake in those counts only in their own problems."  # noqa: E501
        return f"policy_iteration was called with your own {self.evaluation} and {self.improvement}."

    @paused_gc
    def judge(self, settings: PolicyIterationConfig, records: Sequence[CallRecord]) -> Verdict:
        """Each policy optimal by its exact value, V the optimal values, n a whole number of iterations."""
        reading = self._reading(records)
        early = outcome_verdict(records)
        if early is not None:
            if early.status == "timeout":
                return self._timeout(early, records, reading)
            return Verdict(early.status, early.fraction, f"{early.feedback} {reading}", early.measurements)
        graded = [(called_case(record.outcome.call, BETA_AT), record) for record in records]
        problems: list[str] = []
        for case, record in graded:
            problem = self._problem(case, record.outcome.call, record.outcome.value, settings)
            if problem is not None:
                problems.append(problem)
        measurements: dict[str, PlainValue] = {
            "mdps_graded": len(graded),
            "calls_wrong": len(problems),
            "helpers": "grader" if any(record.outcome.call.provided for record in records) else "student",
        }
        if not problems:
            return Verdict(
                "passed",
                1.0,
                f"policy_iteration: an optimal policy (judged by its exact value, ties allowed) and the optimal values on all {len(graded)} MDPs and discounts. {reading}",  # noqa: E501
                measurements,
            )
        more = f" ({len(problems)} of {len(graded)} MDPs wrong.)" if len(problems) > 1 else ""
        return Verdict("failed", 0.0, f"{problems[0]}{more} {reading}", measurements)

    def _problem(
        self, case: GradingCase, call: Call, value: PlainValue, settings: PolicyIterationConfig
    ) -> str | None:
        mdp = case.mdp
        parts = value if isinstance(value, list) and len(value) == 3 else None
        values = None if parts is None else as_vector(parts[0], mdp.n_states)
        policy = None if parts is None else as_policy(parts[1], mdp)
        count = None if parts is None else as_count(parts[2])
        if values is None or policy is None or count is None:
            return f"{call_text(call)} returned {shown(value)}; expected (V, policy, n): the {mdp.n_states} values, one action in 0..{mdp.n_actions - 1} per state, and the number of iterations"  # noqa: E501
        judged = judge_policy(mdp, policy, case.beta)
        if not judged.optimal:
            state = int(np.argmax(judged.shortfall))
            return f"{call_text(call)} returned the policy {describe_values(policy, 8)}, which is not optimal on {mdp.name} at beta = {case.beta:g}: its exact value in state {state} is {judged.values[state]:.6g}, the optimum {judged.optimal_values[state]:.6g}"  # noqa: E501
        best = optimum(case)
        try:
            exact = policy_value(mdp, policy, case.beta)
        except UnboundedValueError:  # judged optimal above, so finite; kept for the type checker
            exact = best
        tolerance = evaluation_tolerance(case, policy, exact, settings.tol)
        if np.max(np.abs(values - best)) > tolerance:
            state = int(np.argmax(np.abs(values - best)))
            return f"{call_text(call)} returned an optimal policy but V = {describe_values(values)}; the optimal values are {describe_values(best)} (state {state}: {values[state]:.6g} against {best[state]:.6g}, tolerance {tolerance:.1e}); return the values of the last policy evaluated"  # noqa: E501
        if not 1 <= count <= settings.maxiter:
            return f"{call_text(call)} returned n = {count}; expected the number of iterations made, 1 to maxiter = {settings.maxiter}"  # noqa: E501
        return None

    def _timeout(self, early: Verdict, records: Sequence[CallRecord], reading: str) -> Verdict:
        index = next(i for i, r in enumerate(records) if r.outcome.status is OutcomeStatus.TIMEOUT)
        case = called_case(records[index].outcome.call, BETA_AT)
        if case.beta < 1 or trapping_states(case.mdp).size == 0:  # every policy has a value there
            return Verdict(early.status, early.fraction, f"{early.feedback}. {reading}", early.measurements)
        cause = f"Likely cause: on {case.mdp.name} at beta = 1 your start policy never converges: a policy whose moves loop forever through costly states (on the lab's example, right from state 0 and left from state 1 walk 0 -> 1 -> 0 at a cost of 1 a lap) has no finite value, so its iterative evaluation never stops. Start from a policy that ends its episodes, such as the all-zeros start or the all-ones start of the 2023 and later texts (np.ones(nS, dtype=int))."  # noqa: E501
        return Verdict(
            early.status, early.fraction, f"{early.feedback}. {cause} {reading}", early.measurements
        )
