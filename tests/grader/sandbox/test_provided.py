"""The grader's own definitions a second reading binds (`grader.sandbox.child.provided`): the lab's value
iteration and policy iteration, and a run_simulation that plays one episode of either gym API and takes
either edition's parameters."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from grader.sandbox.child.provided import PROVIDED, policy_iteration, run_simulation, value_iteration
from reference.oracles.mdp import judge_policy, optimal_solution
from reference.oracles.mdps import frozen_lake, lab_example, windy_grid


def test_value_iteration_gives_the_labs_example_answer_and_count() -> None:
    values, sweeps = value_iteration(lab_example().as_dict(), 4, 4)
    assert values.tolist() == [1.0, 1.0, 1.0, 0.0] and sweeps == 3
    values, _ = value_iteration(lab_example().as_dict(), 4, 4, 0.9)
    assert values.tolist() == pytest.approx([0.9, 1.0, 1.0, 0.0])


@pytest.mark.parametrize(
    ("mdp", "beta"),
    [
        (frozen_lake("4x4", slippery=True), 1.0),
        (windy_grid(), 1.0),
        (windy_grid(), 0.8),
        (lab_example(), 1.0),
    ],
    ids=["lake4", "grid", "grid-0.8", "example"],
)
def test_policy_iteration_finds_an_optimal_policy_and_its_values(mdp: Any, beta: float) -> None:
    values, policy, iterations = policy_iteration(mdp.as_dict(), mdp.n_states, mdp.n_actions, beta)
    assert judge_policy(mdp, policy, beta).optimal
    np.testing.assert_allclose(values, optimal_solution(mdp, beta).values, atol=1e-6)
    assert 1 <= iterations <= 200


class Corridor:
    """Three cells to walk right; the last step pays 1. `classic` serves gym's observation and four results,
    otherwise gym 0.26's pairs and five results."""

    def __init__(self, *, classic: bool) -> None:
        self.classic = classic
        self.state = -1
        self.resets = 0

    def reset(self) -> Any:
        self.state, self.resets = 0, self.resets + 1
        return 0 if self.classic else (0, {})

    def step(self, action: int) -> Any:
        assert action == 2
        self.state += 1
        done = self.state == 3
        reward = 1.0 if done else 0.0
        return (self.state, reward, done, {}) if self.classic else (self.state, reward, done, False, {})


@pytest.mark.parametrize("classic", [True, False], ids=["classic", "gym-0.26"])
@pytest.mark.parametrize(
    ("args", "kwargs", "beta"),
    [
        ((), {}, 1.0),
        ((0.5,), {}, 0.5),
        ((), {"beta": 0.5}, 0.5),
        ((False, 0.5), {}, 0.5),  # 2019-2022: run_simulation(env, policy, render=True, beta=1.0)
        ((True,), {"beta": 0.5}, 0.5),
    ],
    ids=["default", "beta", "beta-keyword", "render-then-beta", "render-keyword-beta"],
)
def test_run_simulation_plays_one_episode_and_discounts_from_k_0(
    classic: bool, args: tuple[Any, ...], kwargs: dict[str, Any], beta: float
) -> None:
    env = Corridor(classic=classic)
    assert run_simulation(env, np.array([2, 2, 2, 0]), *args, **kwargs) == pytest.approx(beta**2)
    assert env.resets == 1 and env.state == 3


def test_every_name_a_second_reading_binds_is_provided() -> None:
    for name in (
        "value_iteration",
        "policy_iteration",
        "run_simulation",
        "iter_policy_eval",
        "compute_policy_v",
    ):
        assert name in PROVIDED
