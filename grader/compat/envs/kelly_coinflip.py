"""KellyCoinflip-v0 and KellyCoinflipGeneralized-v0 (classic gym toy text, later `gym_toytext`)."""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import Env, spaces

from ..errors import InvalidActionError

MAX_WEALTH = 10**12
"""Largest maximum wealth a generalized game draws (its action space counts cents in an int64)."""


class KellyCoinflipEnv(Env[Any, Any]):
    """Bet on a biased coin (Haghani & Dewey 2016): start with $25, at most $250, 300 rounds.

    Rules (classic gym `toy_text/kellycoinflip.py`, `gym_toytext.KellyCoinflipEnv`): an action is a bet
    in pennies (`Discrete(max_wealth * 100)`), capped at the current wealth; the coin wins with
    probability `edge`, paying the bet (else the bet is lost); wealth is capped at `max_wealth`. The
    episode terminates when the wealth falls below a cent, reaches the cap, or the rounds run out; the
    reward is 0 until then and the final wealth at the end. The observation is
    `(array([wealth], float32), rounds left)`.
    """

    metadata = {"render_modes": []}  # noqa: RUF012 (gymnasium reads it from the class)

    def __init__(
        self,
        initial_wealth: float = 25.0,
        edge: float = 0.6,
        max_wealth: float = 250.0,
        max_rounds: int = 300,
    ) -> None:
        """Create the game with the paper's settings by default."""
        self.action_space = spaces.Discrete(int(max_wealth * 100))
        self.observation_space = spaces.Tuple(
            (spaces.Box(0, max_wealth, (1,), np.float32), spaces.Discrete(max_rounds + 1))
        )
        self.edge = edge
        self.initial_wealth = initial_wealth
        self.max_wealth = max_wealth
        self.max_rounds = max_rounds
        self.wealth = initial_wealth
        self.rounds = max_rounds

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        """Start again with the initial wealth and every round left."""
        super().reset(seed=seed)
        self.wealth = self.initial_wealth
        self.rounds = self.max_rounds
        return self._observation(), {}

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Bet `action` pennies on the coin."""
        if not self.action_space.contains(action):
            pennies = int(self.max_wealth * 100) - 1
            raise InvalidActionError(f"KellyCoinflip takes a bet in 0..{pennies} pennies, found {action!r}")
        self.rounds -= 1
        self.wealth = _flip(self.wealth, int(action), self.edge, self.max_wealth, self.np_random)
        done = self.wealth < 0.01 or self.wealth == self.max_wealth or not self.rounds
        return self._observation(), self.wealth if done else 0.0, done, False, {}

    def _observation(self) -> tuple[np.ndarray, int]:
        return np.array([self.wealth], dtype=np.float32), self.rounds


class KellyCoinflipGeneralizedEnv(Env[Any, Any]):
    """The Kelly coinflip game whose edge, wealth cap and number of rounds are hidden random draws.

    Rules (classic gym, `gym_toytext.KellyCoinflipGeneralizedEnv`, by ArthurB and Gwern Branwen): every
    reset draws the edge from Beta(7, 3), the wealth cap from a generalized Pareto distribution (shape
    5, location 200, rounded to dollars) and the rounds from N(300, 25) (rounded); the game is then
    played as `KellyCoinflipEnv`. The observation is `(array([wealth]), rounds elapsed, wins, losses,
    array([highest wealth so far]))`. `clip_distributions=True` redraws caps above the distributions'
    85% (wealth) and 99% (rounds) quantiles so that the spaces keep their size.
    """

    metadata = {"render_modes": []}  # noqa: RUF012 (gymnasium reads it from the class)

    def __init__(
        self,
        initial_wealth: float = 25.0,
        edge_prior_alpha: float = 7,
        edge_prior_beta: float = 3,
        max_wealth_alpha: float = 5.0,
        max_wealth_m: float = 200.0,
        max_rounds_mean: float = 300.0,
        max_rounds_sd: float = 25.0,
        reseed: bool = True,
        clip_distributions: bool = False,
    ) -> None:
        """Create the game; the hidden parameters are drawn at every reset."""
        self.initial_wealth = float(initial_wealth)
        self.edge_prior = (edge_prior_alpha, edge_prior_beta)
        self.max_wealth_alpha = max_wealth_alpha
        self.max_wealth_m = max_wealth_m
        self.max_rounds_mean = max_rounds_mean
        self.max_rounds_sd = max_rounds_sd
        self.clip_distributions = clip_distributions
        self._draw_game()

    def _pareto_quantile(self, probability: float) -> float:
        # scipy's genpareto(c, loc) quantile with scale 1, written out so the layer needs only numpy.
        shape = self.max_wealth_alpha
        return float(self.max_wealth_m + ((1.0 - probability) ** -shape - 1.0) / shape)

    def _draw_max_wealth(self) -> int:
        # The Pareto tail is unbounded; the action space counts cents in an int64, so the draw is capped.
        return min(round(self._pareto_quantile(float(self.np_random.uniform()))), MAX_WEALTH)

    def _draw_game(self) -> None:
        edge = float(self.np_random.beta(*self.edge_prior))
        wealth_bound = round(self._pareto_quantile(0.85)) if self.clip_distributions else None
        max_wealth = self._draw_max_wealth()
        while wealth_bound is not None and max_wealth > wealth_bound:
            max_wealth = self._draw_max_wealth()
        # N(mean, sd)'s 99% quantile: mean + 2.3263 sd.
        rounds_bound = round(self.max_rounds_mean + 2.3263478740 * self.max_rounds_sd)
        max_rounds = round(float(self.np_random.normal(self.max_rounds_mean, self.max_rounds_sd)))
        while self.clip_distributions and max_rounds > rounds_bound:
            max_rounds = round(float(self.np_random.normal(self.max_rounds_mean, self.max_rounds_sd)))
        wealth_space = wealth_bound if wealth_bound is not None else max_wealth
        rounds_space = rounds_bound if self.clip_distributions else max_rounds
        self.action_space = spaces.Discrete(int(wealth_space * 100))
        counter = spaces.Discrete(max(rounds_space, 0) + 1)
        money = spaces.Box(0, wealth_space, (1,), np.float32)
        self.observation_space = spaces.Tuple((money, counter, counter, counter, money))
        self.edge, self.max_wealth, self.max_rounds = edge, float(max_wealth), max_rounds
        self.wealth = self.max_ever_wealth = self.initial_wealth
        self.rounds = max_rounds
        self.rounds_elapsed = self.wins = self.losses = 0

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        """Draw a new edge, cap and number of rounds; start with the initial wealth."""
        super().reset(seed=seed)
        self._draw_game()
        return self._observation(), {}

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Bet `action` pennies on the coin."""
        if not self.action_space.contains(action):
            raise InvalidActionError(f"KellyCoinflipGeneralized takes a bet in pennies, found {action!r}")
        before = self.wealth
        self.rounds -= 1
        self.rounds_elapsed += 1
        self.wealth = _flip(self.wealth, int(action), self.edge, self.max_wealth, self.np_random)
        if self.wealth >= before:
            self.wins += 1
            self.max_ever_wealth = max(self.wealth, self.max_ever_wealth)
        else:
            self.losses += 1
        done = self.wealth < 0.01 or self.wealth == self.max_wealth or not self.rounds
        return self._observation(), self.wealth if done else 0.0, done, False, {}

    def _observation(self) -> tuple[Any, ...]:
        return (
            np.array([self.wealth], dtype=np.float32),
            self.rounds_elapsed,
            self.wins,
            self.losses,
            np.array([self.max_ever_wealth], dtype=np.float32),
        )


def _flip(wealth: float, pennies: int, edge: float, cap: float, np_random: np.random.Generator) -> float:
    bet = min(pennies / 100.0, wealth)
    won = bool(np_random.uniform() < edge)
    return min(cap, wealth + (bet if won else -bet))
