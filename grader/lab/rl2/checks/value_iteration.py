"""The second lab's problem 1: `value_iteration(P, nS, nA, beta=1, tol=1e-8, maxiter=3000)` returns `(V, n)`.

Called once on every MDP and discount of `mdp_calls.cases(seed)` with `(P, nS, nA, beta, tol, maxiter)`
positionally. V must lie within `mdp_calls.value_tolerance` of the exact optimal values
(`reference.oracles.mdp.optimal_solution`); n must be the number of sweeps the lab's algorithm makes from
V = 0 at that tol, the sweep that found the change below tol included (the example: V1, V2, V3 = V2, so
n = 3, as the texts since mid-2022 work it), under one of the readings the text allows
(`mdp_calls.READINGS`: the text's `||V^{k+1} - V^k||` names no norm, so the max norm, the 2-norm and the
1-norm; a sweep in place is accepted too). The texts of 2018 to mid-2022 (editions v2018, v2019) stop
their example at "V2 = [1, 1, 1, 0], which is the solution" without the sweep that finds no change, so
there n may also count only the sweeps that changed V (`changes_counted`: the example's n = 2). A wrong V
is compared with the typical mistakes (`MISTAKES`), each named when it explains every wrong V; a wrong n
by one sweep is named as such.
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
    Reading,
    as_count,
    as_vector,
    bellman_sweep,
    call_text,
    called_case,
    cases,
    close,
    describe_values,
    first_outcomes,
    iterate,
    iterate_norms,
    last_outcomes,
    mdp_call,
    optimum,
    shown,
    value_tolerance,
)
from grader.lab.settings import ProblemConfig, Share
from grader.sandbox.outcome import Call, FunctionInfo, PlainValue
from reference.oracles.mdp import Mdp
from reference.oracles.mdps import GradingCase

FUNCTION = "value_iteration"
JACOBI_MAX = Reading(in_place=False, norm="max")
BETA_AT = 3
"""Where beta is in a call's arguments `(P, nS, nA, beta, tol, maxiter)`."""


class ValueIterationConfig(ProblemConfig):
    """The settings of `value_iteration(P, nS, nA, beta, tol, maxiter)`."""

    tol: float = Field(
        default=1e-8,
        gt=0.0,
        le=1e-4,
        description="The tol passed (the lab's default 1e-8); V's tolerance derives from it.",
    )
    maxiter: int = Field(
        default=3000,
        ge=100,
        le=100_000,
        description="The maxiter passed (the lab's default 3000; the graded MDPs need at most 1200 sweeps at tol 1e-8).",  # noqa: E501
    )
    count_share: Share = Field(
        default=0.25, description="Share of the points for n: right values with a wrong n earn the rest."
    )


@dataclass(frozen=True)
class Expected:
    """What one call should return: the exact values, their tolerance, and the sweep counts accepted."""

    optimum: FloatArray
    tolerance: float
    counts: tuple[int, ...]


@lru_cache(maxsize=CACHED)
def expected(case: GradingCase, tol: float, maxiter: int) -> Expected:
    """The exact optimal values, the tolerance the lab's algorithm earns at `tol`, the accepted sweep counts."""  # noqa: E501
    best = optimum(case)
    sweep = bellman_sweep(case.mdp, case.beta)
    runs = []
    for in_place in sorted({reading.in_place for reading in READINGS}):  # one run stops on every norm
        norms = [reading.norm for reading in READINGS if reading.in_place == in_place]
        stops = iterate_norms(sweep, case.mdp.n_states, tol, maxiter, in_place, norms)
        runs += [(Reading(in_place, norm), *stops[norm]) for norm in norms]
    # The max norm is the smallest, so its stop is the loosest: the other norms' values are closer.
    worst = max(float(np.max(np.abs(values - best))) for reading, values, _ in runs if reading.norm == "max")
    return Expected(best, value_tolerance(case, tol, worst, best), tuple(sorted({n for _, _, n in runs})))


Mistake = Callable[[GradingCase, float, int], FloatArray]


@lru_cache(maxsize=CACHED)
def _lab_values(mdp: Mdp, beta: float, tol: float, maxiter: int, start: float = 0.0) -> FloatArray:
    """V of the lab's value iteration (from the previous V, max-norm stop) on `mdp` at `beta` from
    V = `start`: what a mistake gives, memoised per case (shared: read only)."""
    sweep = bellman_sweep(mdp, beta)
    values = iterate(sweep, mdp.n_states, tol, maxiter, JACOBI_MAX, np.full(mdp.n_states, start))[0]
    values.setflags(write=False)
    return values


MISTAKES: tuple[tuple[str, Mistake], ...] = (
    (
        "beta ignored: your values are those of discount 1 (the discount never applied); multiply the next state's value by beta: p * (r + beta * V[s'])",  # noqa: E501
        lambda case, tol, maxiter: _lab_values(case.mdp, 1.0, tol, maxiter),
    ),
    (
        "first outcome only: your values are those of reading P[s][a][0] alone; on a slippery move every outcome (p, s', r, done) in P[s][a] counts, weighted by p: sum over all of them",  # noqa: E501
        lambda case, tol, maxiter: _lab_values(first_outcomes(case.mdp), case.beta, tol, maxiter),
    ),
    (
        "`=` where `+=` is meant: your values are those of the last outcome of each move alone (each outcome overwrites the one before); add them up with +=",  # noqa: E501
        lambda case, tol, maxiter: _lab_values(last_outcomes(case.mdp), case.beta, tol, maxiter),
    ),
    (
        "values initialised to ones: your values are those of value iteration started from V = 1, which a terminal state that loops to itself (FrozenLake's holes and goal) never clears at discount 1; start from V = np.zeros(nS)",  # noqa: E501
        lambda case, tol, maxiter: _lab_values(case.mdp, case.beta, tol, maxiter, 1.0),
    ),
)
"""Typical mistakes: (what the feedback says, the values they give). Named when one explains every wrong V."""


@dataclass(frozen=True)
class ValueIterationCheck:
    """One call per graded MDP; values exact within the tolerance the tol earns, n by the lab's count.

    Attributes:
        changes_counted: The edition's text also allows n to count only the sweeps that changed V (its
            example stops at "V2 ..., which is the solution"): n - 1 is accepted too.
    """

    changes_counted: bool = False
    function: str = FUNCTION

    def plan(
        self, settings: ValueIterationConfig, functions: Mapping[str, FunctionInfo], seed: int
    ) -> list[Call]:
        """`value_iteration(P, nS, nA, beta, tol, maxiter)` on every case of the seed, positionally."""
        return [
            mdp_call(self.function, case, case.beta, settings.tol, settings.maxiter) for case in cases(seed)
        ]

    def accepted(self, want: Expected) -> tuple[int, ...]:
        """The counts of n accepted for a call: the lab's sweep counts (one less where the text allows)."""
        if not self.changes_counted:
            return want.counts
        return tuple(sorted({*want.counts, *(count - 1 for count in want.counts)}))

    @paused_gc
    def judge(self, settings: ValueIterationConfig, records: Sequence[CallRecord]) -> Verdict:
        """Values against the exact optimum, n against the lab's sweep count; the mistake named."""
        early = outcome_verdict(records)
        if early is not None:
            return early
        graded = [(called_case(record.outcome.call, BETA_AT), record) for record in records]
        shape_problems: list[str] = []
        wrong_values: list[tuple[GradingCase, Call, FloatArray, Expected]] = []
        wrong_counts: list[tuple[GradingCase, Call, int, Expected]] = []
        for case, record in graded:
            want = expected(case, settings.tol, settings.maxiter)
            parts = _pair(record.outcome.value)
            values = None if parts is None else as_vector(parts[0], case.mdp.n_states)
            count = None if parts is None else as_count(parts[1])
            if values is None or count is None:
                found = (
                    f"(V, n) with V {shown(parts[0])} and n {shown(parts[1])}"
                    if parts is not None
                    else shown(record.outcome.value)
                )
                shape_problems.append(
                    f"{call_text(record.outcome.call)} returned {found}; expected (V, n): V the {case.mdp.n_states} values of {case.mdp.name} (an array) and n the number of sweeps (an int)"  # noqa: E501
                )
                continue
            if np.max(np.abs(values - want.optimum)) > want.tolerance:
                wrong_values.append((case, record.outcome.call, values, want))
            elif count not in self.accepted(
                want
            ):  # n is judged where V is right: wrong values take other sweeps
                wrong_counts.append((case, record.outcome.call, count, want))
        measurements: dict[str, PlainValue] = {
            "mdps_graded": len(graded),
            "shapes_wrong": len(shape_problems),
            "values_wrong": len(wrong_values),
            "counts_wrong": len(wrong_counts),
            "tol": settings.tol,
        }
        if shape_problems:
            more = f" ({len(shape_problems)} of {len(graded)} calls)" if len(shape_problems) > 1 else ""
            return Verdict("failed", 0.0, shape_problems[0] + more + ".", measurements)
        problems = []
        if wrong_values:  # a mistake in V changes the sweeps too: n is judged once every V is right
            problems.append(_values_problem(wrong_values, len(graded), settings))
        elif wrong_counts:
            problems.append(_count_problem(wrong_counts, len(graded), self))
        if not problems:
            return Verdict(
                "passed",
                1.0,
                f"value_iteration: the optimal values within the tolerance tol = {settings.tol:g} earns, and n the lab's sweep count, on all {len(graded)} MDPs and discounts.",  # noqa: E501
                measurements,
            )
        fraction = 0.0 if wrong_values else 1.0 - settings.count_share
        return Verdict("failed", fraction, " ".join(problems), measurements)


def _pair(value: PlainValue) -> tuple[PlainValue, PlainValue] | None:
    if isinstance(value, list) and len(value) == 2:
        return value[0], value[1]
    return None


def _values_problem(
    wrong: Sequence[tuple[GradingCase, Call, FloatArray, Expected]],
    total: int,
    settings: ValueIterationConfig,
) -> str:
    case, call, values, want = wrong[0]
    state = int(np.argmax(np.abs(values - want.optimum)))
    message = f"{call_text(call)} returned V = {describe_values(values)}; the exact optimal values of {case.mdp.name} at beta = {case.beta:g} are {describe_values(want.optimum)} (state {state}: {values[state]:.6g} against {want.optimum[state]:.6g}; the tolerance tol = {settings.tol:g} earns here is {want.tolerance:.1e}). {len(wrong)} of {total} MDPs wrong."  # noqa: E501
    for cause, mistake in MISTAKES:
        if all(close(values, mistake(case, settings.tol, settings.maxiter)) for case, _, values, _ in wrong):
            return f"{message} Likely cause: {cause}."
    return message


def _count_problem(
    wrong: Sequence[tuple[GradingCase, Call, int, Expected]], total: int, check: ValueIterationCheck
) -> str:
    _, call, count, want = wrong[0]
    accepted = " or ".join(str(n) for n in check.accepted(want))
    convention = (
        "Your edition's text counts either the sweeps that reached its example's solution (V1 = [0, 1, 1, 0], V2 = [1, 1, 1, 0], which is the solution: n = 2) or every sweep made, the one that finds no change included (n = 3)."  # noqa: E501
        if check.changes_counted
        else "The lab counts every sweep made, the one that finds the change below tol included: on its example V1 = [0, 1, 1, 0], V2 = [1, 1, 1, 0], V3 = V2, so n = 3."  # noqa: E501
    )
    message = f"{call_text(call)} returned n = {count}; the lab's value iteration from V = 0 makes {accepted} sweeps there ({len(wrong)} of {total} MDPs with another n). {convention}"  # noqa: E501
    if all(count + 1 in check.accepted(want) for _, _, count, want in wrong):
        return (
            f"{message} Likely cause: counting the sweeps that changed V instead of the sweeps made (n - 1)."
        )
    if all(count - 1 in check.accepted(want) for _, _, count, want in wrong):
        return f"{message} Likely cause: one sweep counted after the last one made (n + 1)."
    return message
