"""Roulette-v0, the classic gym toy-text game (later `gym_toytext`), as a gymnasium environment."""

from __future__ import annotations

from typing import Any

from gymnasium import Env, spaces

from ..errors import InvalidActionError


class RouletteEnv(Env[Any, Any]):
    """Bet on a roulette wheel with `spots` spots (0 to spots - 1), or walk away.

    Rules (classic gym `toy_text/roulette.py`, `gym_toytext.RouletteEnv`, registered with
    `max_episode_steps=100`): actions 0..spots, the observation is always 0. Betting 0 wins `spots - 1`
    when the wheel shows 0 and loses 1 otherwise; another bet wins 1 when the wheel shows a non-zero
    number of the same parity, else loses 1; the last action (`spots`) walks away: reward 0, the episode
    terminates.
    """

    metadata = {"render_modes": []}  # noqa: RUF012 (gymnasium reads it from the class)

    def __init__(self, spots: int = 37) -> None:
        """Create a wheel with `spots` spots (37: a European wheel)."""
        self.n = spots + 1
        self.action_space = spaces.Discrete(self.n)
        self.observation_space = spaces.Discrete(1)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[int, dict[str, Any]]:
        """Start betting (nothing to set up)."""
        super().reset(seed=seed)
        return 0, {}

    def step(self, action: Any) -> tuple[int, float, bool, bool, dict[str, Any]]:
        """Bet `action` (or walk away with the last action)."""
        if not self.action_space.contains(action):
            raise InvalidActionError(f"Roulette-v0 takes an action in 0..{self.n - 1}, found {action!r}")
        if action == self.n - 1:
            return 0, 0.0, True, False, {}
        value = int(self.np_random.integers(0, self.n - 1))
        if value == action == 0:
            reward = self.n - 2.0
        elif value != 0 and action != 0 and value % 2 == action % 2:
            reward = 1.0
        else:
            reward = -1.0
        return 0, reward, False, False, {}
