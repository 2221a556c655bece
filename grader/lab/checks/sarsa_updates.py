"""SARSA(0) recomputed from the transitions a learner played: the table, typical update mistakes, exploration.

Pure functions of trusted data: the states come from the grader's replay, the actions from the log (each
one is played, so it is what the learner chose). `recompute` applies `Q[s, a] += alpha * (r + gamma *
Q[s', a'] - Q[s, a])` in play order from the zero table, and records for every action whether it was
greedy on the table as it was when the action was chosen (after the step that led to its state, before
that step's update, as SARSA chooses `a'` before updating). `RULES` are the update rules of typical
mistakes, recomputed the same way to name the one a returned table follows.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

Precision = Callable[[float], Any]
"""The type of a table's cells, as a constructor: `float`, or a NumPy scalar type (`np.float32`)."""
TIE_TOLERANCE = 1e-9
"""Values within this (relative to the row's largest magnitude, at least 1) of a row's maximum are
maximisers: two algebraically equal update formulas differ in the last bits."""


@dataclass(frozen=True)
class Transition:
    """One step of an episode: (s, a, r, s', a'), `next_action` None at the episode's last step."""

    state: int
    action: int
    reward: float
    next_state: int
    next_action: int | None


@dataclass(frozen=True)
class EpisodeSteps:
    """The transitions of one played episode and the exploration rate it was played with."""

    transitions: tuple[Transition, ...]
    epsilon: float


@dataclass
class Recomputed:
    """The table SARSA(0) (or a mistaken rule) computes from the transitions, and how the actions fit it.

    Attributes:
        table: The final table.
        last_update: (episode, step), both 0-based, of each cell's last update; absent: never updated.
        non_greedy: Actions that were not a maximiser of their state's row when chosen.
        expected_non_greedy: Sum over actions of epsilon * (non-maximisers / actions): the mean of
            `non_greedy` for an epsilon-greedy learner.
        variance: Sum of p * (1 - p) over the same probabilities.
        actions: Actions judged.
        greedy_on_previous: Non-greedy actions (not first of an episode) that are a maximiser of the
            previous state's row: the trace of choosing `a'` from `s` instead of `s'`.
    """

    table: list[list[float]]
    last_update: dict[tuple[int, int], tuple[int, int]] = field(default_factory=dict)
    non_greedy: int = 0
    expected_non_greedy: float = 0.0
    variance: float = 0.0
    actions: int = 0
    greedy_on_previous: int = 0

    def array(self) -> npt.NDArray[np.float64]:
        """The table as a float64 array."""
        return np.asarray(self.table, dtype=np.float64)


@dataclass(frozen=True)
class Rule:
    """An update rule: how the target bootstraps, whether alpha and gamma are used, the terminal update."""

    name: str
    explanation: str
    bootstrap: Callable[[list[list[float]], Transition], float]
    use_alpha: bool = True
    use_gamma: bool = True
    update_at_end: bool = True
    fixed: tuple[float, float] | None = None
    """(alpha, gamma) the rule uses whatever was passed: the lab's defaults hard-coded."""


def _next_value(table: list[list[float]], step: Transition) -> float:
    if step.next_action is None:
        return max(table[step.next_state])
    return table[step.next_state][step.next_action]


def _best_value(table: list[list[float]], step: Transition) -> float:
    return max(table[step.next_state])


def _taken_value(table: list[list[float]], step: Transition) -> float:
    return table[step.next_state][step.action]


SARSA = Rule("sarsa", "SARSA(0)", _next_value)
RULES: tuple[Rule, ...] = (
    Rule(
        "q_learning",
        "your update used the best next action (max over Q[s']), which is Q-learning; SARSA(0) uses Q[s', a'] of the next action a' you chose and then play",  # noqa: E501
        _best_value,
    ),
    Rule(
        "taken_action",
        "your update used Q[s', a] with the action a just taken instead of the next action a': the next action was chosen after the update. Choose a' from s' first, update with Q[s', a'], then play a'",  # noqa: E501
        _taken_value,
    ),
    Rule(
        "no_alpha",
        "your update replaced Q[s, a] by the target instead of moving it by alpha towards it: use Q[s, a] += alpha * (r + gamma * Q[s', a'] - Q[s, a])",  # noqa: E501
        _next_value,
        use_alpha=False,
    ),
    Rule(
        "no_gamma",
        "your update did not discount Q[s', a'] by gamma: use r + gamma * Q[s', a'] as the target",
        _next_value,
        use_gamma=False,
    ),
    Rule(
        "no_end_update",
        "your table skips the update of the last step of each episode (the drop-off): update Q[s, a] at every step, the last one included (the terminal state's row is zero, so its target is just r)",  # noqa: E501
        _next_value,
        update_at_end=False,
    ),
    Rule(
        "default_parameters",
        "your update used alpha=0.1 and gamma=0.6, the defaults, not the alpha and gamma passed in: use the parameters",  # noqa: E501
        _next_value,
        fixed=(0.1, 0.6),
    ),
)
"""Typical update mistakes, each recomputed from the same transitions; named when it explains the table."""


def is_maximiser(row: Sequence[float], action: int) -> tuple[bool, int]:
    """(whether `action` is one of the row's maximisers, how many maximisers the row has)."""
    best = max(row)
    tolerance = TIE_TOLERANCE * max(1.0, abs(best))
    maximisers = sum(1 for value in row if value >= best - tolerance)
    return row[action] >= best - tolerance, maximisers


def recompute(
    episodes: Sequence[EpisodeSteps],
    shape: tuple[int, int],
    alpha: float,
    gamma: float,
    rule: Rule = SARSA,
    *,
    judge_actions: bool = True,
    precision: Precision = float,
) -> Recomputed:
    """The table `rule` computes from the zero table over the episodes, in play order.

    `precision` is the type of the learner's table cells: `float` (float64), or a NumPy scalar type such
    as `np.float32` for a table made with `dtype=np.float32`. The zero table is made of it, so every update
    rounds as the learner's own NumPy arithmetic does (NumPy 2 keeps a float32 cell's arithmetic with
    Python numbers in float32).

    With `judge_actions`, every action (the first of an episode, and each `a'`) is judged against the
    table as it was when an honest SARSA learner chose it: before the update of the step that reached its
    state. Exploring with `env.action_space.sample()` picks a maximiser too, so an action is non-greedy
    with probability epsilon * (non-maximisers / actions).
    """
    states, actions = shape
    zero = precision(0.0)
    table = [[zero] * actions for _ in range(states)]
    result = Recomputed(table)
    rate, discount = rule.fixed if rule.fixed is not None else (alpha, gamma)
    for number, episode in enumerate(episodes):
        steps = episode.transitions
        if judge_actions and steps:
            _judge(result, table, steps[0].state, steps[0].action, episode.epsilon, None, actions)
        for index, step in enumerate(steps):
            if judge_actions and step.next_action is not None:
                _judge(result, table, step.next_state, step.next_action, episode.epsilon, step.state, actions)
            if step.next_action is None and not rule.update_at_end:
                continue
            bootstrap = rule.bootstrap(table, step)
            target = step.reward + (discount if rule.use_gamma else 1.0) * bootstrap
            row = table[step.state]
            if rule.use_alpha:
                row[step.action] += rate * (target - row[step.action])
            else:
                row[step.action] = target
            result.last_update[(step.state, step.action)] = (number, index)
    return result


def _judge(
    result: Recomputed,
    table: list[list[float]],
    state: int,
    action: int,
    epsilon: float,
    previous: int | None,
    actions: int,
) -> None:
    greedy, maximisers = is_maximiser(table[state], action)
    probability = epsilon * (actions - maximisers) / actions
    result.actions += 1
    result.expected_non_greedy += probability
    result.variance += probability * (1.0 - probability)
    if not greedy:
        result.non_greedy += 1
        if previous is not None and previous != state and is_maximiser(table[previous], action)[0]:
            result.greedy_on_previous += 1


def bernstein_half_width(variance: float, alpha: float) -> float:
    """The t with P(|X - E X| >= t) <= alpha for a sum X of independent [0, 1] variables of this variance.

    Bernstein's inequality, P(|X - E X| >= t) <= 2 exp(-t^2 / (2 variance + 2 t / 3)), solved for t;
    written by hand because no kept library states it (it holds for every sample size, unlike a normal
    approximation of the Poisson-binomial count in its far tail). The learner's probabilities depend on
    its earlier draws, so the centred count is a martingale: this is Freedman's form, at the realised
    predictable variance.
    """
    level = math.log(2.0 / alpha)
    return level / 3.0 + math.sqrt((level / 3.0) ** 2 + 2.0 * variance * level)


def mismatched_cells(
    returned: npt.NDArray[np.float64], expected: npt.NDArray[np.float64], tolerance: float
) -> list[tuple[int, int]]:
    """Cells where the tables differ by more than `tolerance` (absolute, and relative to the value)."""
    wrong = np.abs(returned - expected) > tolerance * np.maximum(1.0, np.abs(expected))
    return [(int(state), int(action)) for state, action in zip(*np.nonzero(wrong), strict=True)]


def first_mismatch(
    cells: Sequence[tuple[int, int]], last_update: dict[tuple[int, int], tuple[int, int]]
) -> tuple[tuple[int, int], tuple[int, int] | None]:
    """The mismatching cell whose last update came first (never-updated cells first of all)."""
    never = [cell for cell in cells if cell not in last_update]
    if never:
        return never[0], None
    cell = min(cells, key=lambda cell: last_update[cell])
    return cell, last_update[cell]
