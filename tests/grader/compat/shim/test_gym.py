"""Tests for the `gym` shim (grader/compat/shim/gym): the classic module surface lab code touches."""

from __future__ import annotations

from ..conftest import RunScript


def test_the_classic_module_surface(run_through_layer: RunScript) -> None:
    result = run_through_layer(
        """
        import gym
        import gym.spaces
        import gymnasium
        from gym import envs, error, logger, spaces, wrappers
        from gym.spaces import Box, Discrete
        from gym.wrappers import TimeLimit

        gym.logger.set_level(40)
        checks = {
            "version": gym.__version__.startswith("0.17.3"),
            "spaces": Discrete is gymnasium.spaces.Discrete and Box is gymnasium.spaces.Box,
            "Env": gym.Env is gymnasium.Env and gym.Wrapper is gymnasium.Wrapper,
            "wrappers": TimeLimit is gymnasium.wrappers.TimeLimit,
            "error": issubclass(gym.error.Error, Exception) and gym.error.Error is gymnasium.error.Error,
            "registry.all": len(list(envs.registry.all())) == len(gymnasium.envs.registry),
            "registry.spec": envs.registry.spec("Blackjack-v0").id == "Blackjack-v1",
            "env_specs": "NChain-v0" in envs.registry.env_specs and "NChain-v0" in envs.registry,
            "logger": gymnasium.logger.min_level == 40 and logger.ERROR == 40,
            "make": type(gym.make("Taxi-v3")).__name__ == "ClassicEnv",
        }
        print(sorted(name for name, ok in checks.items() if not ok))
        """
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout == "[]\n"
