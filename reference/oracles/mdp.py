"""Exact dynamic programming on the finite MDPs of the second lab (Policy Function Iteration / RL 2).

An MDP is the lab's table `P[s][a] = [(probability, next_state, reward, terminal), ...]`. A policy's value
is the expected discounted return `sum beta**k * r_k` (k from 0) until the episode ends, solved exactly as
one linear system, not iterated to a tolerance. The optimal values are the value of an optimal policy,
found by value iteration, polished by exact evaluation and verified to be a fixed point of the Bellman
optimality operator. Policies are judged by their value, never by equality with one list: FrozenLake's
optimal actions tie in many states.

Terminal states hold zero-reward self-loops (FrozenLake) or no outcome of positive probability (the lab's
worked example), so their value is 0 however the table is read. At discount 1 a policy that never ends and
collects nonzero rewards has no finite value (`UnboundedValueError`); one that loops on zero rewards has
the value 0 there, as value iteration from zeros gives.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Literal

import numpy as np
import numpy.typing as npt

from reference.errors import InvalidMdpError, InvalidParameterError, UnboundedValueError

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
Outcome = tuple[float, int, float, bool]
"""One entry of `P[s][a]`: (probability, next state, reward, terminal)."""
Table = Mapping[int, Mapping[int, Sequence[Outcome]]]

CONDITION_LIMIT = 1e12
"""A policy's linear system worse conditioned than this has no finite value (a reward loop at discount 1)."""
FIXED_POINT_TOLERANCE = 1e-9
"""Largest Bellman residual (relative to 1 + |v|) accepted for the optimal values."""
VALUE_ITERATION_SWEEPS = 1_000_000
"""Bound on the sweeps the optimal-value search makes before polishing (8x8 at discount 1 needs ~2 000)."""
SOLUTIONS_CACHED = 256
"""Optimal solutions memoised (per MDP and discount): a grading judges many calls on the same few MDPs."""


@dataclass(frozen=True)
class Mdp:
    """A finite MDP in the lab's format, with its dense arrays.

    Attributes:
        name: short name used in messages.
        table: `table[s][a]` lists the outcomes (probability, next state, reward, terminal), in order.
        n_states: number of states (`nS`).
        n_actions: number of actions (`nA`).
    """

    name: str
    table: tuple[tuple[tuple[Outcome, ...], ...], ...]

    @property
    def n_states(self) -> int:
        """`nS`."""
        return len(self.table)

    @property
    def n_actions(self) -> int:
        """`nA`."""
        return len(self.table[0])

    def as_dict(self) -> dict[int, dict[int, list[Outcome]]]:
        """The table as the lab's nested dictionary of lists (a fresh copy each call)."""
        return {
            state: {action: list(outcomes) for action, outcomes in enumerate(actions)}
            for state, actions in enumerate(self.table)
        }

    def transitions(self) -> FloatArray:
        """`T[s, a, s']`: the probability of moving from s to s' under a (outcomes to one state summed)."""
        moves = np.zeros((self.n_states, self.n_actions, self.n_states))
        for state, actions in enumerate(self.table):
            for action, outcomes in enumerate(actions):
                for probability, next_state, _, _ in outcomes:
                    moves[state, action, next_state] += probability
        return moves

    def expected_rewards(self) -> FloatArray:
        """`R[s, a]`: the expected reward of one step from s under a."""
        rewards = np.zeros((self.n_states, self.n_actions))
        for state, actions in enumerate(self.table):
            for action, outcomes in enumerate(actions):
                rewards[state, action] = sum(probability * reward for probability, _, reward, _ in outcomes)
        return rewards

    def rewarding(self) -> npt.NDArray[np.bool_]:
        """`[s, a]`: whether an outcome of positive probability pays a nonzero reward."""
        return np.array(
            [
                [
                    any(probability > 0 and reward != 0 for probability, _, reward, _ in outcomes)
                    for outcomes in actions
                ]
                for actions in self.table
            ]
        )


def mdp_from_table(name: str, table: Table, n_states: int, n_actions: int) -> Mdp:
    """Build and validate an MDP from the lab's `P`, `nS`, `nA`.

    Raises:
        InvalidMdpError: a state or action is missing, a next state is out of range, a probability is
            negative, or an action's probabilities sum to neither 1 nor 0 (the example's impossible moves).
    """
    if n_states < 1 or n_actions < 1:
        raise InvalidMdpError(
            f"{name}: expected at least one state and one action, found nS={n_states}, nA={n_actions}"
        )
    rows = []
    for state in range(n_states):
        if state not in table:
            raise InvalidMdpError(f"{name}: P has no entry for state {state} of nS={n_states}")
        actions = []
        for action in range(n_actions):
            if action not in table[state]:
                raise InvalidMdpError(
                    f"{name}: P[{state}] has no entry for action {action} of nA={n_actions}"
                )
            outcomes = tuple(
                (float(p), int(next_state), float(reward), bool(done))
                for p, next_state, reward, done in table[state][action]
            )
            _check_outcomes(name, state, action, outcomes, n_states)
            actions.append(outcomes)
        rows.append(tuple(actions))
    return Mdp(name, tuple(rows))


def _check_outcomes(name: str, state: int, action: int, outcomes: tuple[Outcome, ...], n_states: int) -> None:
    where = f"{name}: P[{state}][{action}]"
    if any(not 0 <= next_state < n_states for _, next_state, _, _ in outcomes):
        raise InvalidMdpError(f"{where} leads outside the states 0..{n_states - 1}")
    if any(probability < 0 for probability, _, _, _ in outcomes):
        raise InvalidMdpError(f"{where} has a negative probability")
    total = sum(probability for probability, _, _, _ in outcomes)
    if not (abs(total - 1) <= 1e-9 or total == 0):
        raise InvalidMdpError(
            f"{where}: probabilities sum to {total}, expected 1 (or 0 for an impossible move)"
        )


def checked_discount(beta: float) -> float:
    """The discount factor, which must lie in [0, 1]."""
    if not 0 <= beta <= 1:
        raise InvalidParameterError(f"the discount factor beta must lie in [0, 1], found {beta}")
    return float(beta)


def checked_policy(mdp: Mdp, policy: Sequence[int] | npt.ArrayLike) -> IntArray:
    """A deterministic policy as an integer array with one action per state."""
    actions = np.asarray(policy)
    if (
        actions.shape != (mdp.n_states,)
        or not np.all(np.isfinite(actions))
        or np.any(actions != np.round(actions))
    ):
        raise InvalidParameterError(
            f"{mdp.name}: a policy is {mdp.n_states} whole action numbers, found {np.asarray(policy)!r}"
        )
    integral = actions.astype(np.int64)
    if np.any((integral < 0) | (integral >= mdp.n_actions)):
        raise InvalidParameterError(
            f"{mdp.name}: actions lie in 0..{mdp.n_actions - 1}, found {integral.tolist()}"
        )
    return integral


def q_values(mdp: Mdp, values: npt.ArrayLike, beta: float) -> FloatArray:
    """`Q[s, a] = sum p * (r + beta * v[s'])`: one look-ahead on `values` (exact, no iteration)."""
    v = np.asarray(values, dtype=np.float64)
    return mdp.expected_rewards() + checked_discount(beta) * mdp.transitions() @ v


def _silent_states(mdp: Mdp, policy: IntArray) -> npt.NDArray[np.bool_]:
    """States from which the policy can never meet a nonzero reward: their value is 0 at any discount."""
    moves = mdp.transitions()[np.arange(mdp.n_states), policy] > 0
    live = mdp.rewarding()[np.arange(mdp.n_states), policy].copy()
    while True:
        grown = live | (moves & live[np.newaxis, :]).any(axis=1)
        if np.array_equal(grown, live):
            return ~live
        live = grown


def policy_value(mdp: Mdp, policy: Sequence[int] | npt.ArrayLike, beta: float) -> FloatArray:
    """The exact value of a deterministic policy: `(I - beta T_pi) v = r_pi` solved on the states that can
    still meet a reward.

    Raises:
        UnboundedValueError: at discount 1 the policy loops forever through nonzero rewards.
    """
    return return_moments(mdp, policy, beta).mean


@dataclass(frozen=True)
class ReturnMoments:
    """Mean and variance of the discounted return `sum beta**k * r_k` of one episode, per start state."""

    mean: FloatArray
    variance: FloatArray


def return_moments(
    mdp: Mdp, policy: Sequence[int] | npt.ArrayLike, beta: float, *, steps: int | None = None
) -> ReturnMoments:
    """The exact mean and variance of one episode's discounted return under a deterministic policy.

    Args:
        mdp: the MDP.
        policy: one action per state.
        beta: the discount factor in [0, 1].
        steps: a time limit (the episode is cut after this many steps, as `gym.make`'s TimeLimit does);
            None for none. With a limit the moments come from the exact finite-horizon recursion.

    Raises:
        UnboundedValueError: without a limit, at discount 1, the policy loops through nonzero rewards.
    """
    beta = checked_discount(beta)
    actions = checked_policy(mdp, policy)
    states = np.arange(mdp.n_states)
    moves = mdp.transitions()[states, actions]
    first, second = _reward_moments(mdp, actions)
    if steps is not None:
        if steps < 0:
            raise InvalidParameterError(f"a time limit is a number of steps >= 0, found {steps}")
        mean = np.zeros(mdp.n_states)
        square = np.zeros(mdp.n_states)
        for _ in range(steps):
            # E[(r + beta G')^2] = E[r^2] + 2 beta E[r G'] + beta^2 E[G'^2]; G' depends on r only via s'.
            square = second + 2 * beta * _reward_times_next(mdp, actions, mean) + beta**2 * moves @ square
            mean = first + beta * moves @ mean
        return ReturnMoments(mean, np.maximum(square - mean**2, 0.0))
    live = ~_silent_states(mdp, actions)
    mean = np.zeros(mdp.n_states)
    square = np.zeros(mdp.n_states)
    if live.any():
        inner = moves[np.ix_(live, live)]
        mean[live] = _solve(mdp, np.eye(int(live.sum())) - beta * inner, first[live])
        cross = _reward_times_next(mdp, actions, mean)
        square[live] = _solve(
            mdp, np.eye(int(live.sum())) - beta**2 * inner, second[live] + 2 * beta * cross[live]
        )
    return ReturnMoments(mean, np.maximum(square - mean**2, 0.0))


def _reward_moments(mdp: Mdp, actions: IntArray) -> tuple[FloatArray, FloatArray]:
    first = np.zeros(mdp.n_states)
    second = np.zeros(mdp.n_states)
    for state, action in enumerate(actions):
        for probability, _, reward, _ in mdp.table[state][action]:
            first[state] += probability * reward
            second[state] += probability * reward * reward
    return first, second


def _reward_times_next(mdp: Mdp, actions: IntArray, values: FloatArray) -> FloatArray:
    """`E[r * v(s')]` per state: the reward and the next state's return are tied through the outcome."""
    cross = np.zeros(mdp.n_states)
    for state, action in enumerate(actions):
        for probability, next_state, reward, _ in mdp.table[state][action]:
            cross[state] += probability * reward * values[next_state]
    return cross


def _solve(mdp: Mdp, matrix: FloatArray, right: FloatArray) -> FloatArray:
    if np.linalg.cond(matrix) > CONDITION_LIMIT:
        raise UnboundedValueError(
            f"{mdp.name}: the policy loops forever through nonzero rewards, so its return at discount 1 has "
            "no finite value"
        )
    solution: FloatArray = np.linalg.solve(matrix, right).astype(np.float64)
    return solution


def greedy_gaps(
    mdp: Mdp, values: npt.ArrayLike, policy: Sequence[int] | npt.ArrayLike, beta: float
) -> FloatArray:
    """Per state, how far the policy's action falls short of the best one-step look-ahead on `values`.

    An `extract_policy`/`policy_improvement` answer is right when every gap is 0 up to rounding: any of
    several tied actions is.
    """
    look_ahead = q_values(mdp, values, beta)
    actions = checked_policy(mdp, policy)
    gaps: FloatArray = look_ahead.max(axis=1) - look_ahead[np.arange(mdp.n_states), actions]
    return gaps


@dataclass(frozen=True)
class OptimalSolution:
    """The exact optimal values of an MDP at one discount, and one optimal policy (of many, with ties)."""

    values: FloatArray
    policy: IntArray
    beta: float


def optimal_solution(mdp: Mdp, beta: float) -> OptimalSolution:
    """The optimal values, exact: the value of an optimal policy solved as a linear system.

    Value iteration from zeros approaches the values; a policy is then chosen among the (nearly) greedy
    actions: the first best action in each state, as the lab takes it, when that policy achieves the
    values, otherwise one that moves towards the end of the episode (at discount 1 the first best action
    may loop on a tie forever); it is evaluated exactly, improved while an action is strictly better, and
    its values are checked to be a fixed point of the Bellman optimality operator.

    A pure function of the MDP and the discount, memoised: each call returns its own copy of the arrays.

    Raises:
        UnboundedValueError: no optimal policy with finite values is found (the oracle's domain: discount
            below 1, or at discount 1 MDPs whose optimal policies end their episodes).
    """
    solved = _optimal_solution(mdp, checked_discount(beta))
    return OptimalSolution(solved.values.copy(), solved.policy.copy(), solved.beta)


@lru_cache(maxsize=SOLUTIONS_CACHED)
def _optimal_solution(mdp: Mdp, beta: float) -> OptimalSolution:
    rewards, moves = mdp.expected_rewards(), mdp.transitions()
    values = np.zeros(mdp.n_states)
    for _ in range(VALUE_ITERATION_SWEEPS):
        updated = (rewards + beta * moves @ values).max(axis=1)
        change = np.max(np.abs(updated - values))
        values = updated
        if change <= 1e-15 * (1 + np.max(np.abs(values))):
            break
    look_ahead = q_values(mdp, values, beta)
    policy = _ending_policy(mdp, look_ahead)
    first_greedy = np.argmax(look_ahead, axis=1).astype(np.int64)
    try:
        # The lab's own choice (first best action) is kept when it is optimal: its episodes are short.
        if np.all(values - policy_value(mdp, first_greedy, beta) <= 1e-9 * (1 + np.abs(values))):
            policy = first_greedy
    except UnboundedValueError:
        pass
    for _ in range(mdp.n_states * mdp.n_actions + 1):
        values = policy_value(mdp, policy, beta)
        look_ahead = q_values(mdp, values, beta)
        better = look_ahead.max(axis=1) > look_ahead[np.arange(mdp.n_states), policy] + 1e-12 * (
            1 + np.abs(values)
        )
        if not better.any():
            break
        policy = _ending_policy(mdp, look_ahead, keep=policy, change=better)
    residual = np.max(np.abs(q_values(mdp, values, beta).max(axis=1) - values) / (1 + np.abs(values)))
    if residual > FIXED_POINT_TOLERANCE:
        raise UnboundedValueError(
            f"{mdp.name}: no optimal policy with finite values at beta={beta} (residual {residual:.1e})"
        )
    return OptimalSolution(values, policy, beta)


def _ending_policy(
    mdp: Mdp,
    look_ahead: FloatArray,
    *,
    keep: IntArray | None = None,
    change: npt.NDArray[np.bool_] | None = None,
) -> IntArray:
    """A policy of nearly greedy actions that, where it can, moves closer to a silent (terminal) state.

    States are taken in rounds outward from the terminal states: a state joins when one of its nearly greedy
    actions may reach a state that joined before; of those actions it takes the one most likely to, so that
    episodes stay short (an optimal policy at discount 1 may otherwise wander for thousands of steps).
    States that join no round keep their first greedy action. With `keep`, only states in `change` get a
    new action.
    """
    best = look_ahead.max(axis=1, keepdims=True)
    greedy = look_ahead >= best - 1e-9 * (1 + np.abs(best))
    policy = np.argmax(greedy, axis=1).astype(np.int64) if keep is None else keep.copy()
    free = np.ones(mdp.n_states, dtype=bool) if change is None else change
    probabilities = mdp.transitions()
    moves = probabilities > 0
    settled = _absorbing(mdp) | ~free
    while True:
        joining = ~settled & (greedy & (moves & settled[np.newaxis, np.newaxis, :]).any(axis=2)).any(axis=1)
        if not joining.any():
            break
        for state in np.flatnonzero(joining):
            # Of the greedy actions, the one most likely to step into a settled state: short episodes.
            into_settled = np.where(greedy[state], probabilities[state][:, settled].sum(axis=1), -1.0)
            policy[state] = int(np.argmax(into_settled))
        settled |= joining
    return policy


def _absorbing(mdp: Mdp) -> npt.NDArray[np.bool_]:
    """States every action of which stays put with reward 0 (or has no outcome of positive probability)."""
    moves, rewarding = mdp.transitions(), mdp.rewarding()
    elsewhere = ~np.eye(mdp.n_states, dtype=bool)[:, np.newaxis, :]
    stays: npt.NDArray[np.bool_] = ~np.any((moves > 0) & elsewhere, axis=(1, 2))
    return stays & ~rewarding.any(axis=1)


def terminal_states(mdp: Mdp) -> IntArray:
    """The states where episodes end: every action stays put with reward 0, or has no possible outcome."""
    return np.flatnonzero(_absorbing(mdp)).astype(np.int64)


def trapping_states(mdp: Mdp) -> IntArray:
    """The states from which some policy never reaches a terminal state (empty: every policy ends).

    The largest set C of non-terminal states in which every state has an action whose every outcome of
    positive probability stays in C, found by removing, until none is left to remove, each state with no
    such action. Exact for deterministic policies: if C is not empty, the policy that takes such an action
    in every state of C never leaves it; if a deterministic policy can be trapped (some state of its chain
    cannot reach a terminal state), the states its chain reaches from there form such a set, which no
    removal takes away. A move with no outcome of positive probability (the lab's example writes its
    impossible moves so) stays nowhere, so it cannot trap.
    """
    moves = mdp.transitions() > 0
    inside = ~_absorbing(mdp)
    while True:
        stays = ~np.any(moves & ~inside[np.newaxis, np.newaxis, :], axis=2) & moves.any(axis=2)
        kept = inside & stays.any(axis=1)
        if np.array_equal(kept, inside):
            return np.flatnonzero(inside).astype(np.int64)
        inside = kept


@dataclass(frozen=True)
class PolicyJudgement:
    """How a policy compares with the optimum, state by state."""

    values: FloatArray
    optimal_values: FloatArray
    shortfall: FloatArray

    @property
    def optimal(self) -> bool:
        """Whether the policy achieves the optimal value in every state (up to rounding)."""
        return bool(np.all(self.shortfall <= 1e-9 * (1 + np.abs(self.optimal_values))))


def judge_policy(mdp: Mdp, policy: Sequence[int] | npt.ArrayLike, beta: float) -> PolicyJudgement:
    """Evaluate a policy exactly and compare it with the optimal values.

    A policy that loops forever through nonzero rewards at discount 1 has no finite value; it is judged as
    falling infinitely short in the states it cannot leave (`-inf` values there).
    """
    optimum = optimal_solution(mdp, beta).values
    try:
        values = policy_value(mdp, policy, beta)
    except UnboundedValueError:
        values = np.full(mdp.n_states, -np.inf)
    return PolicyJudgement(values, optimum, optimum - values)


def lab_value_iteration(
    mdp: Mdp,
    beta: float,
    *,
    tol: float = 1e-8,
    maxiter: int = 3000,
    norm: Literal["max", "l2"] = "max",
    in_place: bool = False,
) -> tuple[FloatArray, int]:
    """The lab's own value iteration, as a correct student writes it: the reference for sweep counts.

    Sweeps of the Bellman optimality update from V = 0 until the change between two sweeps is below `tol`
    (in the sup norm or, as `np.linalg.norm` gives, the 2-norm); `n` counts every sweep made, the one that
    found the change small included (the lab's example: n = 3). `in_place` updates V state by state
    (Gauss-Seidel), which some students do and which may take fewer sweeps.

    Returns:
        (V, n): the values after the last sweep and the number of sweeps.
    """
    beta = checked_discount(beta)
    rewards, moves = mdp.expected_rewards(), mdp.transitions()
    values = np.zeros(mdp.n_states)
    for sweep in range(1, maxiter + 1):
        previous = values.copy()
        if in_place:
            for state in range(mdp.n_states):
                values[state] = np.max(rewards[state] + beta * moves[state] @ values)
        else:
            values = (rewards + beta * moves @ values).max(axis=1)
        difference = values - previous
        change = np.max(np.abs(difference)) if norm == "max" else float(np.linalg.norm(difference))
        if change < tol:
            return values, sweep
    return values, maxiter
