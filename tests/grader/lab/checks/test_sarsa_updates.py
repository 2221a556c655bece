"""The pure SARSA(0) core: exact recomputation, mistaken rules, the greedy judgement, Bernstein's bound."""

import math

import numpy as np
import pytest

from grader.lab.checks.sarsa_updates import (
    RULES,
    EpisodeSteps,
    Transition,
    bernstein_half_width,
    first_mismatch,
    is_maximiser,
    mismatched_cells,
    recompute,
)

# Two plays of a two-step episode: state 0 -(action 0, -1)-> state 1 -(action 1, +20)-> state 2 (terminal).
EPISODE = EpisodeSteps((Transition(0, 0, -1.0, 1, 1), Transition(1, 1, 20.0, 2, None)), epsilon=0.5)
RULE = {rule.name: rule for rule in RULES}


def test_sarsa_is_recomputed_exactly_in_play_order() -> None:
    result = recompute([EPISODE, EPISODE], (3, 2), alpha=0.5, gamma=0.9)
    # Episode 1: Q[0,0] = 0.5 * (-1 + 0.9 * 0) = -0.5, then Q[1,1] = 0.5 * 20 = 10.
    # Episode 2: Q[0,0] = -0.5 + 0.5 * (-1 + 0.9 * 10 + 0.5) = 3.75, then Q[1,1] = 10 + 0.5 * (20 - 10) = 15.
    assert result.table == [[3.75, 0.0], [0.0, 15.0], [0.0, 0.0]]
    assert result.last_update == {(0, 0): (1, 0), (1, 1): (1, 1)}


def test_each_action_is_judged_on_the_table_as_it_was_when_chosen() -> None:
    result = recompute([EPISODE, EPISODE], (3, 2), alpha=0.5, gamma=0.9)
    # Episode 1: all ties (greedy, p 0). Episode 2: action 0 in state 0 after Q[0,0] = -0.5 is not greedy
    # (p = 0.5 * 1/2); action 1 in state 1 is chosen before episode 2's first update, Q[1] = [0, 10]: greedy,
    # though exploring could have picked action 0 (p = 0.5 * 1/2 again).
    assert (result.actions, result.non_greedy) == (4, 1)
    assert result.expected_non_greedy == pytest.approx(0.5)
    assert result.variance == pytest.approx(2 * 0.25 * 0.75)


@pytest.mark.parametrize(
    ("rule", "table"),
    [
        ("no_alpha", [[17.0, 0.0], [0.0, 20.0], [0.0, 0.0]]),
        ("no_gamma", [[4.25, 0.0], [0.0, 15.0], [0.0, 0.0]]),
        ("no_end_update", [[-0.75, 0.0], [0.0, 0.0], [0.0, 0.0]]),
        ("default_parameters", [[-0.07, 0.0], [0.0, 3.8], [0.0, 0.0]]),
    ],
)
def test_the_mistaken_rules_compute_their_own_tables(rule: str, table: list[list[float]]) -> None:
    result = recompute([EPISODE, EPISODE], (3, 2), 0.5, 0.9, RULE[rule], judge_actions=False)
    np.testing.assert_allclose(result.array(), table, rtol=1e-12)


def test_ties_within_the_tolerance_are_all_maximisers() -> None:
    assert is_maximiser([1.0, 1.0 - 1e-12, 0.5], 1) == (True, 2)
    assert is_maximiser([1.0, 0.9, 0.5], 1) == (False, 1)


def test_the_first_mismatch_is_the_earliest_last_update_and_never_updated_cells_come_first() -> None:
    last = {(0, 0): (1, 0), (1, 1): (0, 5)}
    assert first_mismatch([(0, 0), (1, 1)], last) == ((1, 1), (0, 5))
    assert first_mismatch([(0, 0), (2, 1)], last) == ((2, 1), None)


def test_cells_differ_beyond_the_tolerance_only() -> None:
    expected = np.array([[1.0, -7.725], [0.0, 0.0]])
    returned = expected + np.array([[1e-12, 0.0], [0.0, 1e-3]])
    assert mismatched_cells(returned, expected, 1e-8) == [(1, 1)]


@pytest.mark.parametrize("variance", [0.0, 10.0, 1e4])
def test_bernsteins_bound_meets_its_level(variance: float) -> None:
    alpha = 1e-6
    t = bernstein_half_width(variance, alpha)
    assert 2 * math.exp(-(t**2) / (2 * variance + 2 * t / 3)) == pytest.approx(alpha)


def _float32_learner(episodes: list[EpisodeSteps], alpha: float, gamma: float) -> np.ndarray:
    """A learner's own float32 table, updated with the lab's `+=` line on the same transitions."""
    q = np.zeros((3, 2), dtype=np.float32)
    for episode in episodes:
        for step in episode.transitions:
            bootstrap = (
                q[step.next_state, step.next_action]
                if step.next_action is not None
                else q[step.next_state].max()
            )
            q[step.state, step.action] += alpha * (
                step.reward + gamma * bootstrap - q[step.state, step.action]
            )
    return q


def test_a_float32_table_is_recomputed_with_float32_rounding() -> None:
    episodes = [EPISODE] * 6
    learner = _float32_learner(episodes, 0.3, 0.7).astype(np.float64)
    in_float32 = recompute(episodes, (3, 2), 0.3, 0.7, precision=np.float32, judge_actions=False).array()
    in_float64 = recompute(episodes, (3, 2), 0.3, 0.7, judge_actions=False).array()
    assert np.array_equal(learner, in_float32)  # the same rounding, step for step
    assert mismatched_cells(learner, in_float64, 1e-8) != []  # which float64 arithmetic does not reproduce
    assert mismatched_cells(learner, in_float64, 1e-5) == []
