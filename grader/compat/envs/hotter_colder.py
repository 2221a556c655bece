"""HotterColder-v0, the classic gym toy-text game (later `gym_toytext`), as a gymnasium environment."""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces

from ..errors import InvalidActionError
from .guessing_game import NO_GUESS_YET, HiddenNumberEnv, guess_side


class HotterColderEnv(HiddenNumberEnv):
    """Guess a hidden number; the reward grows the closer the guess is ("hotter").

    Rules (classic gym `toy_text/hotter_colder.py`, `gym_toytext.HotterColder`, registered with
    `max_episode_steps=200`): reset draws the target uniformly from [-1000, 1000) and observes 0; a guess
    is a `Box(-2000, 2000, (1,), float32)`; the observation is 1 (guess below the target), 2 (equal) or
    3 (above); the reward is `((min(guess, target) + 2000) / (max(guess, target) + 2000)) ** 2`; the
    episode ends after 200 guesses (the environment itself never terminates).
    """

    metadata = {"render_modes": []}  # noqa: RUF012 (gymnasium reads it from the class)

    def __init__(self) -> None:
        """Create the game with the classic range (1000) and bounds (2000)."""
        self.range = 1000
        self.bounds = 2000
        self.guess_max = 200
        self.action_space = spaces.Box(-self.bounds, self.bounds, (1,), np.float32)
        self.observation_space = spaces.Discrete(4)
        self.number = 0.0
        self.guess_count = 0

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[int, dict[str, Any]]:
        """Draw a new target; observe 0 (no guess yet)."""
        self._hide_number(seed)
        return NO_GUESS_YET, self._info()

    def step(self, action: Any) -> tuple[int, float, bool, bool, dict[str, Any]]:
        """Take one guess; see the class docstring for the observation and reward."""
        guess = np.asarray(action, dtype=np.float64).reshape(-1)
        if guess.shape != (1,) or not -self.bounds <= guess[0] <= self.bounds:
            raise InvalidActionError(
                f"HotterColder-v0 takes one guess in [-{self.bounds}, {self.bounds}], found {action!r}"
            )
        value = float(guess[0])
        observation = guess_side(value, self.number)
        reward = ((min(value, self.number) + self.bounds) / (max(value, self.number) + self.bounds)) ** 2
        self.guess_count += 1
        return observation, reward, False, self.guess_count >= self.guess_max, self._info()

    def _info(self) -> dict[str, Any]:
        return {"number": self.number, "guesses": self.guess_count}
