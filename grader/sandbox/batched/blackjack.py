"""Replay many Blackjack episodes cheaply: gymnasium's `BlackjackEnv` rules on plain lists, seeded draws.

A seeded `reset` of the scalar env builds a new `numpy.random.Generator` and then draws every card
with `Generator.choice(deck)`, which converts the deck to an array at each draw, and every `step` checks
its action against the action space; together they cost more than the student's whole game. Here each
episode is dealt from its seed's draws (`grader.sandbox.batched.draws.seeded_draws`: the element
`Generator.choice` would return) and played by the rules of `BlackjackEnv.reset` and `step` (gymnasium
1.x), written over plain lists: the same cards from gymnasium's own `deck`, the same draws for the dealer's
suit and face that `reset` makes, the dealer drawing to 17, `natural` and `sab` read from the env made.
`grader.sandbox.replay` re-checks every batch against the real, seeded scalar env, which stays the
authority for every mismatch; `tests/grader/sandbox/test_replay.py` compares thousands of games.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import gymnasium
from gymnasium.envs.toy_text import blackjack as gymnasium_blackjack
from gymnasium.envs.toy_text.blackjack import BlackjackEnv

from grader.sandbox.batched.draws import SeededDraws, seeded_draws
from grader.sandbox.batched.replayer import BatchedEpisode
from grader.sandbox.episode_log import EpisodeLog

ENV_IDS = frozenset({"Blackjack-v1"})
GAME_ARGUMENTS = frozenset({"natural", "sab"})
SUITS = 4
"""`reset` draws the dealer's top card's suit (for rendering) after the four cards ..."""
FACES = 3
"""... and, when that card is worth 10, its face (J, Q or K): draws the next cards depend on."""


class BlackjackReplayer:
    """`BatchedReplayer` for `Blackjack-v1` with only `natural`/`sab` arguments (no time limit)."""

    def is_batchable(self, log: EpisodeLog) -> bool:
        """Blackjack with bool `natural`/`sab` only, no reset options, actions 0 or 1."""
        if log.env_id not in ENV_IDS or log.reset_options is not None or not log.actions:
            return False
        if not GAME_ARGUMENTS.issuperset(log.env_kwargs):
            return False
        if any(type(value) is not bool for value in log.env_kwargs.values()):
            return False
        return set(map(type, log.actions)) == {int} and set(log.actions) <= {0, 1}

    def replay(self, logs: Sequence[EpisodeLog]) -> list[BatchedEpisode]:
        """Replay Blackjack logs sharing `env_id` and `env_kwargs`, each from its own seed's card draws.

        Raises:
            TypeError: the registered env is not gymnasium's `BlackjackEnv`.
        """
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            wrapped = gymnasium.make(logs[0].env_id, disable_env_checker=True, **logs[0].env_kwargs)
        blackjack = wrapped.unwrapped
        if type(blackjack) is not BlackjackEnv or wrapped.spec is None or wrapped.spec.max_episode_steps:
            wrapped.close()
            raise TypeError(f"{logs[0].env_id} is not gymnasium's BlackjackEnv without a time limit")
        rules = _Rules(tuple(gymnasium_blackjack.deck), blackjack.natural, blackjack.sab)
        wrapped.close()
        draws = seeded_draws([log.reset_seed for log in logs])
        return [_play(rules, log, cards) for log, cards in zip(logs, draws, strict=True)]


@dataclass(frozen=True)
class _Rules:
    deck: tuple[int, ...]
    natural: bool
    sab: bool


def _play(rules: _Rules, log: EpisodeLog, cards: SeededDraws) -> BatchedEpisode:
    deck, draw = rules.deck, cards.choice
    dealer = [draw(deck), draw(deck)]
    player = [draw(deck), draw(deck)]
    cards.bounded(SUITS)
    if dealer[0] == 10:
        cards.bounded(FACES)
    observations: list[Any] = [_observation(player, dealer[0])]
    rewards: list[float] = []
    terminated: list[bool] = []
    for action in log.actions:
        if action:  # hit
            player.append(draw(deck))
            ended = _total(player) > 21
            reward = -1.0 if ended else 0.0
        else:  # stick: the dealer draws to 17
            ended = True
            while _total(dealer) < 17:
                dealer.append(draw(deck))
            reward = _reward(rules, player, dealer)
        observations.append(_observation(player, dealer[0]))
        rewards.append(reward)
        terminated.append(ended)
        if ended:
            break
    return BatchedEpisode(observations, rewards, terminated, [False] * len(rewards), terminated[-1])


def _total(hand: list[int]) -> int:
    total = sum(hand)
    return total + 10 if 1 in hand and total + 10 <= 21 else total


def _observation(player: list[int], dealer_card: int) -> tuple[int, int, int]:
    total = sum(player)
    usable = 1 in player and total + 10 <= 21
    return (total + 10 if usable else total, dealer_card, int(usable))


def _score(hand: list[int]) -> int:
    total = _total(hand)
    return 0 if total > 21 else total


def _reward(rules: _Rules, player: list[int], dealer: list[int]) -> float:
    mine, theirs = _score(player), _score(dealer)
    reward = float(mine > theirs) - float(mine < theirs)
    player_natural = sorted(player) == [1, 10]
    if rules.sab and player_natural and sorted(dealer) != [1, 10]:
        return 1.0
    if not rules.sab and rules.natural and player_natural and reward == 1.0:
        return 1.5
    return reward
