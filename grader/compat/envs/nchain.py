"""NChain-v0, the classic gym chain walk, as a gymnasium environment."""

from __future__ import annotations

from typing import Any

import gymnasium
from gymnasium import spaces

from ..errors import InvalidActionError


class NChainEnv(gymnasium.Env[Any, Any]):
    """n-Chain: walk a chain of states for a large reward at its end, or go back for a small one.

    Rules (classic gym 0.9 to 0.17, `gym/envs/toy_text/nchain.py`, registered as `NChain-v0` with
    `max_episode_steps=1000`; the environment itself never terminates; Strens (2000), section 6.1):

    - states 0..n-1, start in state 0; actions 0 = forward, 1 = backward;
    - with probability `slip` the agent slips and the opposite action is taken;
    - backward: go back to state 0 and receive `small`;
    - forward: move one state along the chain for reward 0, or, at the last state, stay there and
      receive `large`.

    Randomness comes from `np_random` (one uniform draw per step), so a seeded reset reproduces an
    episode exactly. Rewards are Python ints, as in the classic source.
    """

    metadata = {"render_modes": []}  # noqa: RUF012 (gymnasium reads it from the class)

    def __init__(self, n: int = 5, slip: float = 0.2, small: int = 2, large: int = 10) -> None:
        """Create the chain.

        Args:
            n: number of states in the chain.
            slip: probability that the opposite action is taken.
            small: reward for going backward.
            large: reward for going forward at the end of the chain.
        """
        self.n = n
        self.slip = slip
        self.small = small
        self.large = large
        self.state = 0
        self.action_space = spaces.Discrete(2)
        self.observation_space = spaces.Discrete(n)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[int, dict[str, Any]]:
        """Put the player back at the start of the chain (state 0)."""
        super().reset(seed=seed)
        self.state = 0
        return self.state, {}

    def step(self, action: int) -> tuple[int, int, bool, bool, dict[str, Any]]:
        """Move along the chain; see the class docstring for the rules.

        Raises:
            InvalidActionError: `action` is not 0 or 1.
        """
        if not self.action_space.contains(action):
            raise InvalidActionError(
                f"NChain-v0 expects action 0 (forward) or 1 (backward), found {action!r}. "
                "Pass env.action_space.sample() or an int in range(env.action_space.n)."
            )
        backward = bool(action)
        if self.np_random.random() < self.slip:
            backward = not backward
        if backward:
            reward = self.small
            self.state = 0
        elif self.state < self.n - 1:
            reward = 0
            self.state += 1
        else:
            reward = self.large
        return self.state, reward, False, False, {}
