"""Tests for grader.compat.envs.nchain: the classic NChain-v0 rules, checked draw by draw."""

from __future__ import annotations

import gymnasium
import pytest
from gymnasium.utils import seeding

from grader.compat import InvalidActionError, NChainEnv, register_envs

FORWARD, BACKWARD = 0, 1


def _expected_walk(seed: int, actions: list[int], slip: float = 0.2) -> list[tuple[int, int]]:
    """The classic rules written out independently, fed the same uniform draws as the env."""
    draws, _ = seeding.np_random(seed)
    state, walk = 0, []
    for action in actions:
        backward = action == BACKWARD
        if draws.random() < slip:
            backward = not backward
        if backward:
            state, reward = 0, 2
        elif state < 4:
            state, reward = state + 1, 0
        else:
            reward = 10
        walk.append((state, reward))
    return walk


@pytest.mark.parametrize("seed", range(50))
def test_each_step_follows_the_classic_rules_with_the_env_s_own_draws(seed: int) -> None:
    actions = [FORWARD] * 30 + [BACKWARD] * 5 + [FORWARD, BACKWARD] * 10
    env = NChainEnv()
    env.reset(seed=seed)
    walk = []
    for action in actions:
        state, reward, terminated, truncated, info = env.step(action)
        assert (terminated, truncated, info) == (False, False, {})
        walk.append((state, reward))
    assert walk == _expected_walk(seed, actions)


@pytest.mark.parametrize(
    ("action", "start", "expected"),
    [(FORWARD, 0, (1, 0)), (FORWARD, 4, (4, 10)), (BACKWARD, 3, (0, 2))],
    ids=["forward-moves-on", "forward-at-end-pays-large", "backward-returns-and-pays-small"],
)
def test_without_slipping(action: int, start: int, expected: tuple[int, int]) -> None:
    env = NChainEnv(slip=0.0)
    env.reset(seed=0)
    env.state = start
    assert env.step(action)[:2] == expected


def test_always_slipping_reverses_the_action() -> None:
    env = NChainEnv(slip=1.0)
    env.reset(seed=0)
    assert env.step(BACKWARD)[:2] == (1, 0)


def test_reset_returns_to_the_start() -> None:
    env = NChainEnv()
    env.reset(seed=0)
    env.state = 3
    assert env.reset() == (0, {})


@pytest.mark.parametrize("action", [2, -1, 0.5, "0"], ids=["2", "-1", "0.5", "str"])
def test_invalid_actions_are_refused(action: object) -> None:
    env = NChainEnv()
    env.reset(seed=0)
    with pytest.raises(InvalidActionError, match=r"NChain-v0 expects action 0 \(forward\) or 1 \(backward\)"):
        env.step(action)  # type: ignore[arg-type]


def test_registered_with_the_classic_1000_step_limit() -> None:
    register_envs()
    env = gymnasium.make("NChain-v0")
    env.reset(seed=0)
    results = [env.step(0) for _ in range(1000)]
    assert [index for index, result in enumerate(results) if result[2] or result[3]] == [999]
    assert results[-1][3] is True


def test_register_envs_is_idempotent() -> None:
    register_envs()
    spec = gymnasium.spec("NChain-v0")
    register_envs()
    assert gymnasium.spec("NChain-v0") is spec
