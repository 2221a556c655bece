"""Exact returns of Taxi policies within the time limit, and the optimal Q-table by value iteration.

The model is read from gymnasium itself: `gym.make("Taxi-v4").unwrapped.P` (the transition table the
environment samples from) and `initial_state_distrib` (uniform over the 300 states with the taxi anywhere,
the passenger at one of the four pads and a different destination). With the default arguments (`Taxi-v3`
in the lab is `Taxi-v4` with defaults) every action has exactly one outcome, so the model is three
(500, 6) tables: next state, reward, and whether the step ends the episode (a successful drop-off).
`gym.make` adds a 200-step time limit; the returns below count the rewards of at most `max_steps` steps.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import gymnasium as gym
import numpy as np
import numpy.typing as npt

from reference.errors import InvalidParameterError, InvalidQTableError, UnexpectedEnvironmentError

TAXI_ID = "Taxi-v4"
STATES = 500
ACTIONS = 6
TIME_LIMIT = 200
VALUE_ITERATION_TOLERANCE = 1e-12
"""`optimal_q_table` stops once its result is within this distance (max norm) of the fixed point."""

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class ReturnMoments:
    """Mean and variance of the total (undiscounted) reward of one episode from the reset distribution.

    Attributes:
        mean: expected total reward.
        variance: variance of the total reward.
    """

    mean: float
    variance: float

    @property
    def std(self) -> float:
        """Standard deviation of the total reward."""
        return float(np.sqrt(self.variance))


@dataclass(frozen=True)
class TaxiModel:
    """Taxi's deterministic dynamics as arrays indexed by `[state, action]`."""

    next_state: npt.NDArray[np.int64]
    reward: FloatArray
    terminates: npt.NDArray[np.bool_]
    initial_distribution: FloatArray


def random_policy_return(max_steps: int = TIME_LIMIT) -> ReturnMoments:
    """Exact return of the uniformly random policy (each of the 6 actions with probability 1/6).

    Args:
        max_steps: the time limit; 200 is what `gym.make("Taxi-v4")` enforces.

    Returns:
        Mean and variance of the episode's total reward.

    Raises:
        InvalidParameterError: `max_steps` is negative.
    """
    return _policy_return(np.full((STATES, ACTIONS), 1.0 / ACTIONS), _checked_steps(max_steps))


def greedy_policy_return(q_table: npt.ArrayLike, max_steps: int = TIME_LIMIT) -> ReturnMoments:
    """Exact return of acting greedily on a Q-table, as the lab's `taxi()` does.

    The action in state `s` is `np.argmax(q_table[s])`: the first maximum on ties, and the first NaN if a
    row holds one (numpy's rule). Both the policy and the environment are deterministic, so the return is
    a function of the start state; the moments are over the reset distribution.

    Args:
        q_table: array-like of real numbers with shape (500, 6).
        max_steps: the time limit; 200 is what `gym.make("Taxi-v4")` enforces.

    Returns:
        Mean and variance of the episode's total reward.

    Raises:
        InvalidQTableError: `q_table` does not have shape (500, 6) or holds something other than numbers.
        InvalidParameterError: `max_steps` is negative.
    """
    greedy_actions = np.argmax(checked_q_table(q_table), axis=1)
    policy = np.zeros((STATES, ACTIONS))
    policy[np.arange(STATES), greedy_actions] = 1.0
    return _policy_return(policy, _checked_steps(max_steps))


def optimal_return(max_steps: int = TIME_LIMIT) -> ReturnMoments:
    """Exact return of the best possible policy within the time limit (undiscounted).

    Args:
        max_steps: the time limit; 200 is what `gym.make("Taxi-v4")` enforces.

    Returns:
        Mean and variance over the reset distribution of the largest achievable total reward.

    Raises:
        InvalidParameterError: `max_steps` is negative.
    """
    model = taxi_model()
    best = np.zeros(STATES)
    for _ in range(_checked_steps(max_steps)):
        best = np.max(model.reward + np.where(model.terminates, 0.0, best[model.next_state]), axis=1)
    return _moments(model.initial_distribution, best, best**2)


def optimal_q_table(gamma: float = 0.6) -> FloatArray:
    """The optimal action values for discount `gamma`, by value iteration from an all-zero table.

    Iterates `Q(s, a) = r(s, a) + gamma * max_a' Q(s', a')` (no bootstrap after a drop-off) until the
    largest change `delta` guarantees `gamma / (1 - gamma) * delta <= VALUE_ITERATION_TOLERANCE`
    (1e-12), i.e. every entry is within 1e-12 of the fixed point.

    Args:
        gamma: discount factor in [0, 1).

    Returns:
        A new (500, 6) float64 array.

    Raises:
        InvalidParameterError: `gamma` is outside [0, 1).
    """
    if not 0.0 <= gamma < 1.0:
        raise InvalidParameterError(
            f"expected a discount factor gamma in [0, 1), found {gamma!r}; value iteration only converges "
            f"for gamma < 1 (the lab uses 0.6)"
        )
    model = taxi_model()
    q_table = np.zeros((STATES, ACTIONS))
    while True:
        bootstrap = np.where(model.terminates, 0.0, q_table.max(axis=1)[model.next_state])
        updated = model.reward + gamma * bootstrap
        delta = float(np.max(np.abs(updated - q_table)))
        q_table = updated
        if gamma * delta <= VALUE_ITERATION_TOLERANCE * (1.0 - gamma):
            return q_table


def checked_q_table(q_table: npt.ArrayLike) -> FloatArray:
    """`q_table` as a float64 array after checking it can be a Taxi Q-table.

    Raises:
        InvalidQTableError: wrong shape, or entries that are not real numbers.
    """
    try:
        array = np.asarray(q_table)
    except (TypeError, ValueError) as error:
        raise InvalidQTableError(
            f"expected a Taxi Q-table: an array of numbers with shape ({STATES}, {ACTIONS}); "
            f"could not convert the {type(q_table).__name__} to an array ({error})"
        ) from None
    if array.shape != (STATES, ACTIONS):
        raise InvalidQTableError(
            f"expected a Taxi Q-table with shape ({STATES}, {ACTIONS}) (one row per state, one column per "
            f"action), found shape {array.shape}; build it as np.zeros((env.observation_space.n, "
            f"env.action_space.n))"
        )
    if array.dtype.kind not in "biuf":
        raise InvalidQTableError(
            f"expected a Taxi Q-table of real numbers, found dtype {array.dtype}; "
            f"store the action values as floats"
        )
    return array.astype(np.float64)


@cache
def taxi_model() -> TaxiModel:
    """Taxi-v4's dynamics (default arguments) read from gymnasium's transition table `P`.

    Raises:
        UnexpectedEnvironmentError: some action has more than one outcome (gymnasium changed Taxi).
    """
    env = gym.make(TAXI_ID).unwrapped
    next_state = np.zeros((STATES, ACTIONS), dtype=np.int64)
    reward = np.zeros((STATES, ACTIONS))
    terminates = np.zeros((STATES, ACTIONS), dtype=np.bool_)
    for state, actions in env.P.items():  # type: ignore[attr-defined]
        for action, outcomes in actions.items():
            if len(outcomes) != 1 or outcomes[0][0] != 1.0:
                raise UnexpectedEnvironmentError(
                    f"expected one certain outcome per action in {TAXI_ID}, found {outcomes!r} for state "
                    f"{state}, action {action}; the Taxi oracle needs gymnasium's deterministic Taxi "
                    f"(gymnasium 1.4 with default arguments)"
                )
            _, next_state[state, action], reward[state, action], terminates[state, action] = outcomes[0]
    initial_distribution = np.asarray(env.initial_state_distrib, dtype=np.float64)  # type: ignore[attr-defined]
    env.close()
    for array in (next_state, reward, terminates, initial_distribution):
        array.flags.writeable = False
    return TaxiModel(next_state, reward, terminates, initial_distribution)


def _policy_return(policy: FloatArray, max_steps: int) -> ReturnMoments:
    """First and second moments of the return, by backward induction over the remaining steps."""
    model = taxi_model()
    continues = ~model.terminates
    first = np.zeros(STATES)
    second = np.zeros(STATES)
    for _ in range(max_steps):
        next_first = np.where(continues, first[model.next_state], 0.0)
        next_second = np.where(continues, second[model.next_state], 0.0)
        step_first = model.reward + next_first
        step_second = model.reward**2 + 2.0 * model.reward * next_first + next_second
        first = np.sum(policy * step_first, axis=1)
        second = np.sum(policy * step_second, axis=1)
    return _moments(model.initial_distribution, first, second)


def _moments(initial: FloatArray, first: FloatArray, second: FloatArray) -> ReturnMoments:
    mean = float(initial @ first)
    return ReturnMoments(mean=mean, variance=max(float(initial @ second) - mean**2, 0.0))


def _checked_steps(max_steps: int) -> int:
    if isinstance(max_steps, bool) or not isinstance(max_steps, int | np.integer) or max_steps < 0:
        raise InvalidParameterError(
            f"expected max_steps as a non-negative integer (Taxi's time limit is {TIME_LIMIT}), "
            f"found {max_steps!r}"
        )
    return int(max_steps)


DETOUR_WALL = ((2, 1, 2), (2, 2, 3))
"""An extra wall in the middle row between columns 1 and 2, as (row, column, blocked action): east from
(2, 1) and west from (2, 2). Left and right still meet through rows 3 and 4: every trip ends, by a detour."""


def detour_q_table(gamma: float = 0.6) -> FloatArray:
    """Optimal action values for Taxi with `DETOUR_WALL` added, ties broken towards the first action.

    Greedy play on it in the real Taxi takes exactly the walled map's optimal routes (each move it picks
    behaves the same without the wall), so every episode ends, later than optimal play: its exact return is
    `greedy_policy_return(detour_q_table())` (5.757 per episode against the optimum's 7.930). Subtracting
    1e-6 per action index makes every row's maximum unique (values of distinct actions differ far more), so
    any greedy rule, first maximiser or a random one among ties, plays the same policy.

    Raises:
        InvalidParameterError: `gamma` is outside [0, 1).
    """
    return walled_q_table(DETOUR_WALL, gamma) - 1e-6 * np.arange(ACTIONS)


def walled_q_table(walls: tuple[tuple[int, int, int], ...], gamma: float = 0.6) -> FloatArray:
    """Optimal action values for Taxi with extra walls, by value iteration (ties left as they fall).

    Args:
        walls: (row, column, action) triples: that move from that cell is blocked (the taxi stays, the
            step costs -1000, so no greedy policy takes it); block both sides of a wall to make one.
        gamma: discount factor in [0, 1).

    Returns:
        A new (500, 6) float64 array. Where every blocked move has an unblocked alternative, greedy play
        on it in the real Taxi takes the walled map's optimal routes.

    Raises:
        InvalidParameterError: `gamma` is outside [0, 1).
    """
    if not 0.0 <= gamma < 1.0:
        raise InvalidParameterError(f"expected a discount factor gamma in [0, 1), found {gamma!r}")
    model = taxi_model()
    next_state, reward = model.next_state.copy(), model.reward.copy()
    blocked: dict[tuple[int, int], list[int]] = {(row, column): [] for row, column, _ in walls}
    for row, column, action in walls:
        blocked[(row, column)].append(action)
    for state in range(STATES):
        for action in blocked.get((state // 100, (state // 20) % 5), ()):
            next_state[state, action], reward[state, action] = state, -1000.0
    q_table = np.zeros((STATES, ACTIONS))
    while True:
        bootstrap = np.where(model.terminates, 0.0, q_table.max(axis=1)[next_state])
        updated = reward + gamma * bootstrap
        delta = float(np.max(np.abs(updated - q_table)))
        q_table = updated
        if gamma * delta <= VALUE_ITERATION_TOLERANCE * (1.0 - gamma):
            return q_table
