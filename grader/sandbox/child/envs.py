"""The lab's games as the child deals them: gymnasium's own classes, with the same steps done cheaper.

A student's Taxi call plays about two million steps, and gymnasium spends most of each one on numpy
calls over one-element arrays: `categorical_sample` (an array, a cumulative sum and an argmax to pick
the only transition there is) and `action_mask` (a new array, filled from the map, at every step).
Blackjack draws each card with `Generator.choice(deck)`, which turns the 13-card deck into an array at
every draw. The classes below are subclasses of gymnasium's, and `cheaper` swaps an env made by
`gymnasium.make` to them in place: same attributes, same spec, same wrappers, same name. Each step gives
what gymnasium's gives, object for object (observation, reward, flags, info, the env's own state), and
draws the same numbers from the env's generator, so the generator ends in the same state: the student
cannot tell, and the parent's replay in gymnasium's own env finds the same game.
`tests/grader/sandbox/test_envs.py` holds them to that, step by step against gymnasium's classes.

Whatever these shortcuts do not cover (Taxi's rainy or fickle variants, a human render mode, an action
that is not a plain 0 or 1 for Blackjack, a state the student set by hand) is passed to gymnasium's
own code.
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium.envs.toy_text import blackjack, taxi

_DECK = tuple(blackjack.deck)
_DECK_SIZE = len(_DECK)
_SUITS = ("C", "D", "H", "S")
_FACES = ("J", "Q", "K")
_STATE_TYPES = (int, np.int64)


class TaxiEnv(taxi.TaxiEnv):
    """gymnasium's Taxi: a step with one possible transition skips `categorical_sample`'s arrays.

    `categorical_sample` of one transition draws one number and always picks it (a cumulative sum of one
    probability, compared with one draw below 1): the step draws that number and takes the transition.
    Action masks are computed once per state, the first time they are asked for, by gymnasium's own
    `action_mask`, and each step returns a fresh copy (a student may write into it).
    """

    _masks: list[np.ndarray] | None = None

    def step(self, a: Any) -> tuple[int, Any, Any, bool, dict[str, Any]]:
        transitions = self.P[self.s][a]
        if len(transitions) != 1 or self.fickle_passenger or self.render_mode == "human":
            return super().step(a)
        self.np_random.random()  # the draw `categorical_sample` makes to pick the only transition
        p, s, r, t = transitions[0]
        self.lastaction = a
        self.s = s
        return int(s), r, t, False, {"prob": p, "action_mask": self.action_mask(s)}

    def action_mask(self, state: int) -> np.ndarray:
        masks = self._masks
        if masks is None:
            states = self.observation_space.n  # type: ignore[attr-defined]
            masks = self._masks = [super(TaxiEnv, self).action_mask(state) for state in range(states)]
        if type(state) in _STATE_TYPES and 0 <= state < len(masks):
            return masks[state].copy()
        return super().action_mask(state)


class BlackjackEnv(blackjack.BlackjackEnv):
    """gymnasium's Blackjack: each card is `deck[integers(0, 13)]`, which is what `choice(deck)` draws.

    `Generator.choice` of a 13-item list without probabilities draws one `integers(0, 13)` (64-bit) and
    indexes the list; the suit and face shown by `render` are drawn the same way (`choice` of 4 and of 3)
    and kept as the numpy strings `choice` returns. An action other than an int or numpy integer 0 or 1
    (`action_space.sample()` gives a numpy integer) takes gymnasium's check of the action space; a
    generator that is not numpy's own `Generator` (a student's `RandomState`, say) takes gymnasium's
    `choice`.
    """

    def step(self, action: Any) -> tuple[tuple[int, int, int], float, bool, bool, dict[str, Any]]:
        if (
            not (type(action) is int or isinstance(action, np.integer))
            or not 0 <= action <= 1
            or self.render_mode == "human"
            or type(self.np_random) is not np.random.Generator
        ):
            return super().step(action)
        integers = self.np_random.integers
        if action:
            self.player.append(_card(integers))
            if blackjack.is_bust(self.player):
                terminated = True
                reward = -1.0
            else:
                terminated = False
                reward = 0.0
        else:
            terminated = True
            while blackjack.sum_hand(self.dealer) < 17:
                self.dealer.append(_card(integers))
            reward = blackjack.cmp(blackjack.score(self.player), blackjack.score(self.dealer))
            if self.sab and blackjack.is_natural(self.player) and not blackjack.is_natural(self.dealer):
                reward = 1.0
            elif not self.sab and self.natural and blackjack.is_natural(self.player) and reward == 1.0:
                reward = 1.5
        return self._get_obs(), reward, terminated, False, {}

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[tuple[int, int, int], dict[str, Any]]:
        kept = self._np_random
        if self.render_mode == "human" or (
            seed is None and kept is not None and type(kept) is not np.random.Generator
        ):
            return super().reset(seed=seed, options=options)
        gymnasium.Env.reset(self, seed=seed)
        integers = self.np_random.integers
        self.dealer = [_card(integers), _card(integers)]
        self.player = [_card(integers), _card(integers)]
        dealer_card_value = self.dealer[0]
        self.dealer_top_card_suit = np.str_(_SUITS[integers(0, len(_SUITS))])
        if dealer_card_value == 1:
            self.dealer_top_card_value_str = "A"
        elif dealer_card_value == 10:
            self.dealer_top_card_value_str = np.str_(_FACES[integers(0, len(_FACES))])
        else:
            self.dealer_top_card_value_str = str(dealer_card_value)
        return self._get_obs(), {}


def _card(integers: Any) -> int:
    """gymnasium's `draw_card`: `int(np_random.choice(deck))`, drawn as `choice` draws it."""
    return _DECK[integers(0, _DECK_SIZE)]


_CHEAPER: dict[type, type] = {taxi.TaxiEnv: TaxiEnv, blackjack.BlackjackEnv: BlackjackEnv}
"""gymnasium's class -> the cheaper one, of the same name (what `str(env)` and `type(env).__name__` show)."""


def cheaper(env: gymnasium.Env[Any, Any]) -> None:
    """Deal `env`'s game with the cheaper class when it is exactly one of gymnasium's lab games."""
    cheaper_class = _CHEAPER.get(type(env))
    if cheaper_class is not None:
        env.__class__ = cheaper_class
