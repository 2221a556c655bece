"""What the second lab's pure problems share: the MDPs they are called on, how a returned value is read, and
the tolerance the lab's own algorithm earns at the `tol` it is passed.

The MDPs are `reference.oracles.mdps.grading_cases(seed)`, all of the lab's kind (the lab's example,
FrozenLake 4x4/8x8 slippery and deterministic, a windy 2x3 grid on which every policy ends; discounts 1, 0.9
and 0.8; then random MDPs of the lab's shape drawn from the problem's seed, held out), each passed
as an `MdpArgument` (the child hands the function a fresh `{s: {a: [(p, s', r, done), ...]}}`), with `nS`
and `nA` as plain ints, positionally as the templates order the parameters.

**Tolerance of a value** (`value_tolerance`): iterating to a tolerance stops short of the exact values. Below
discount 1 the theorem bound holds: a sweep operator that is a beta-contraction in the max norm, stopped
when a sweep changes V by less than `tol`, leaves V within `beta * tol / (1 - beta)` of its fixed point
(the 2-norm is at least the max norm, so a 2-norm stop is as close). At discount 1 there is no contraction
bound; the tolerance is then twice the largest error the lab's own algorithm makes at that `tol` on that
MDP, over the readings the lab text allows (a sweep from the previous V or in place, stopped on the max
norm, the loosest), computed by the exact oracle. Every tolerance adds `ROUNDING * (1 + max |V|)`.

**Seeded plans, judged from the calls.** A check's `plan(settings, functions, seed)` draws its cases, values
and policies from the problem's seed (`cases(seed)`, `reference.oracles.mdps.seeded_draw`); its `judge`
reads what each call was asked from the call itself (`called_case`: each record's `outcome.call` is the
parent's planned `Call`, never anything the child sent), so plan and judge cannot disagree and the parent
knows every MDP it judges against.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import numpy.typing as npt

from grader.lab.checks.integrity import NO_EPISODES
from grader.sandbox.outcome import Call, MdpArgument, PlainValue
from reference.oracles.mdp import Mdp, optimal_solution
from reference.oracles.mdps import GradingCase, grading_cases

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

ROUNDING = 1e-9
"""Relative floating-point slack of every value compared (sums of a few hundred products in another order)."""
CACHED = 512
"""Entries each memo of the rl2 checks keeps (cases, draws, exact values, tolerances): a grading seed adds
its own, so a long-running grader keeps the recent ones only, bounded."""
DIAGNOSIS_TOLERANCE = 1e-5
"""How close returned values must be to a typical mistake's values for the feedback to name it (the
mistakes differ from the right values and from each other by 1e-2 or more on the graded MDPs)."""


@lru_cache(maxsize=CACHED)
def cases(seed: int | None = None) -> tuple[GradingCase, ...]:
    """The MDPs and discounts every pure problem is graded on under a problem's seed, the lab's example
    first, the held-out random MDPs last (without a seed, the public cases alone)."""
    return grading_cases(seed)


def called_case(call: Call, beta_at: int) -> GradingCase:
    """The MDP and discount a planned call was asked about, read from the call (`P` first, beta at `beta_at`).

    Its key is the MDP's name (the seeds of the draws are the plan's business, not the judge's).
    """
    argument = call.args[0]
    if not isinstance(argument, MdpArgument):
        raise TypeError(f"{call.function}: the first argument planned is not an MDP table: {argument!r}")
    return _case(argument.name, argument.table, float(call.args[beta_at]))


@lru_cache(maxsize=CACHED)
def _case(name: str, table: Any, beta: float) -> GradingCase:
    return GradingCase(name, Mdp(name, table), beta, "read from the planned call")


@lru_cache(maxsize=CACHED)
def optimum(case: GradingCase) -> FloatArray:
    """The exact optimal values of a case (do not change the array: it is shared)."""
    return optimal_solution(case.mdp, case.beta).values


def mdp_argument(mdp: Mdp) -> MdpArgument:
    """The table of `mdp` as a call's argument."""
    return MdpArgument(mdp.name, mdp.table)


def mdp_call(function: str, case: GradingCase, *rest: PlainValue) -> Call:
    """`function(P, nS, nA, *rest)` on a case's MDP: one call, no episodes, a small result frame.

    Recorded with a budget of no episodes, so the result frame is bounded by the sandbox's allowance for a
    return value alone (4 MiB), and a function that plays an environment is refused.
    """
    mdp = case.mdp
    return Call(
        function,
        (mdp_argument(mdp), mdp.n_states, mdp.n_actions, *rest),
        record_episodes=True,
        budget=NO_EPISODES,
    )


def call_text(call: Call) -> str:
    """`value_iteration(P of FrozenLake 4x4 (slippery), 16, 4, 0.9, 1e-08, 3000)` for feedback."""
    arguments = []
    for argument in call.args:
        if isinstance(argument, np.ndarray):
            arguments.append(f"<array of {argument.size}>")
        else:
            arguments.append(repr(argument))
    return f"{call.function}({', '.join(arguments)})"


def as_vector(value: PlainValue, size: int) -> FloatArray | None:
    """A returned value as `size` finite floats, or None when it is not one (a tuple, wrong length, text).

    An array of any shape holding exactly `size` numbers is read flat (a column vector is still the values);
    bools are not numbers.
    """
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in "iuf" or value.size != size:
            return None
        flat = value.astype(np.float64).reshape(size)
    elif isinstance(value, list) and len(value) == size:
        if not all(type(item) in (int, float) for item in value):
            return None
        flat = np.array(value, dtype=np.float64)
    else:
        return None
    return flat if bool(np.all(np.isfinite(flat))) else None


def as_policy(value: PlainValue, mdp: Mdp) -> IntArray | None:
    """A returned policy as one action number per state, or None (whole floats such as 2.0 count)."""
    flat = as_vector(value, mdp.n_states)
    if flat is None or np.any(flat != np.round(flat)):
        return None
    actions = flat.astype(np.int64)
    return actions if bool(np.all((actions >= 0) & (actions < mdp.n_actions))) else None


def as_count(value: PlainValue) -> int | None:
    """A returned iteration count (an int, or a whole float), or None."""
    if type(value) is int:
        return value
    if type(value) is float and math.isfinite(value) and value == round(value):
        return int(value)
    return None


def shown(value: PlainValue) -> str:
    """What a returned value is, for feedback: `an array of shape (4,) and dtype int64`, `a sequence of 2
    items`, `a str`."""
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape} and dtype {value.dtype}"
    if isinstance(value, list):
        return f"a sequence of {len(value)} item{'' if len(value) == 1 else 's'}"
    name = type(value).__name__
    return f"{'an' if name[0] in 'aeiou' else 'a'} {name}"


def describe_values(values: Sequence[float] | npt.NDArray[Any], limit: int = 6) -> str:
    """A short readable list of values: `[0.9, 1, 1, 0]`, or the first `limit` and how many more."""
    listed = ", ".join(f"{float(value):.6g}" for value in list(values)[:limit])
    more = len(values) - limit
    return f"[{listed}{f', ... ({more} more)' if more > 0 else ''}]"


def value_tolerance(case: GradingCase, tol: float, worst: float, optimum: FloatArray) -> float:
    """How far returned values may lie from the exact ones (module docstring).

    Args:
        case: The MDP and discount.
        tol: The tolerance the function was passed.
        worst: The largest error of the lab's own algorithm at `tol` (over the readings the text allows).
        optimum: The exact values.
    """
    rounding = ROUNDING * (1.0 + float(np.max(np.abs(optimum))))
    theorem = case.beta * tol / (1.0 - case.beta) if case.beta < 1 else 0.0
    return max(theorem, 2.0 * worst) + rounding


@dataclass(frozen=True)
class Reading:
    """A way the lab's text may be read when iterating to a tolerance: sweep from the previous V (the
    text's `V^{k+1}` from `V^k`) or update V in place; stop on the max norm or the 2-norm."""

    in_place: bool
    norm: str


NORMS = ("max", "l2", "l1")
"""The norms of `||V^{k+1} - V^k||`, which the texts do not name: `np.max(np.abs(...))`, `np.linalg.norm`
and `np.sum(np.abs(...))`."""
READINGS = tuple(Reading(in_place, norm) for in_place in (False, True) for norm in NORMS)
"""Every reading of "iterate until the change is below tol" the grader accepts (n may follow any)."""


def stop_change(difference: FloatArray, norm: str) -> float:
    """The change between two sweeps in a reading's norm."""
    if norm == "max":
        return float(np.max(np.abs(difference)))
    return float(np.linalg.norm(difference)) if norm == "l2" else float(np.sum(np.abs(difference)))


def iterate(
    sweep: Callable[[FloatArray, bool], FloatArray],
    size: int,
    tol: float,
    maxiter: int,
    reading: Reading,
    start: FloatArray | None = None,
) -> tuple[FloatArray, int]:
    """Sweeps of `sweep(V, in_place)` from `start` (zeros) until the change is below `tol`: (V, sweeps made)."""  # noqa: E501
    return iterate_norms(sweep, size, tol, maxiter, reading.in_place, (reading.norm,), start)[reading.norm]


def iterate_norms(
    sweep: Callable[[FloatArray, bool], FloatArray],
    size: int,
    tol: float,
    maxiter: int,
    in_place: bool,
    norms: Sequence[str],
    start: FloatArray | None = None,
) -> dict[str, tuple[FloatArray, int]]:
    """`iterate` stopped on each of `norms`, from one run: the sweeps do not depend on the norm, only where
    they stop, so each norm gets the (V, sweeps made) its own `iterate` would give."""
    values = np.zeros(size) if start is None else start.copy()
    stopped: dict[str, tuple[FloatArray, int]] = {}
    for count in range(1, maxiter + 1):
        updated = sweep(values, in_place)
        difference = updated - values
        values = updated
        for norm in norms:
            if norm not in stopped and stop_change(difference, norm) < tol:
                stopped[norm] = (values, count)
        if len(stopped) == len(set(norms)):
            return stopped
    return {norm: stopped.get(norm, (values, maxiter)) for norm in norms}


def bellman_sweep(
    mdp: Mdp, beta: float, policy: IntArray | None = None
) -> Callable[[FloatArray, bool], FloatArray]:
    """One sweep of the Bellman optimality update (or, with `policy`, of the policy's own equation).

    Each sweep returns a new array (`values` is left as it was). `beta * T @ V` is `(beta * T) @ V`, so the
    product `beta * T` is made once, not once a sweep (the same numbers).
    """
    rewards, scaled = mdp.expected_rewards(), beta * mdp.transitions()
    states = np.arange(mdp.n_states)
    rows = list(zip(rewards, scaled, strict=True))
    actions = None if policy is None else [int(action) for action in policy]

    def sweep(values: FloatArray, in_place: bool) -> FloatArray:
        if not in_place:
            look = rewards + scaled @ values
            return look.max(axis=1) if policy is None else look[states, policy]
        updated = values.copy()
        for state, (reward, move) in enumerate(rows):
            look = reward + move @ updated
            updated[state] = look.max() if actions is None else look[actions[state]]
        return updated

    return sweep


def first_outcomes(mdp: Mdp) -> Mdp:
    """The MDP as read by `P[s][a][0]`: each move's first outcome only (probabilities as listed)."""
    return Mdp(f"{mdp.name}, first outcomes", tuple(tuple(o[:1] for o in actions) for actions in mdp.table))


def last_outcomes(mdp: Mdp) -> Mdp:
    """The MDP as read by `q[a] = p * (...)` in a loop over outcomes (`=` for `+=`): the last one only."""
    return Mdp(f"{mdp.name}, last outcomes", tuple(tuple(o[-1:] for o in actions) for actions in mdp.table))


def close(values: FloatArray, other: FloatArray, tolerance: float = DIAGNOSIS_TOLERANCE) -> bool:
    """Whether two value vectors agree within `tolerance` everywhere."""
    return bool(np.max(np.abs(values - other)) <= tolerance)
