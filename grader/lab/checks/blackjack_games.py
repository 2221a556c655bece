"""Counting replayed Blackjack games and the decisions taken in them (shared by problems 1 and 2)."""

from __future__ import annotations

from collections.abc import Sequence

from grader.lab.checks.integrity import Episode
from grader.lab.checks.values import GameCounts

HIT = 1
GAME_STEPS = 16
"""Steps recorded per game: a hand busts after at most ten draws; room for steps after the end."""


def player_sum(observation: object) -> int:
    """The player's sum as the observation shows it (``(sum, dealer card, usable ace)``)."""
    return int(observation[0])  # type: ignore[index]


def count_games(episodes: Sequence[Episode]) -> GameCounts:
    """Wins, draws and total reward of replayed games (a game's total reward is +1, 0 or -1)."""
    totals = [episode.total_reward for episode in episodes]
    return GameCounts(
        games=len(totals),
        wins=sum(1 for total in totals if total > 0),
        draws=sum(1 for total in totals if total == 0),
        reward_total=sum(totals),
    )


def _group(total: int) -> str:
    # Hands up to 11 cannot bust, so they form one group; 12..21 each get their own.
    return "sum<=11" if total <= 11 else f"sum={total}"


def hits_by_sum(episodes: Sequence[Episode]) -> dict[str, tuple[int, int]]:
    """Per player-sum group, (draws, decisions), in increasing sum order."""
    counts: dict[str, list[int]] = {}
    for episode in episodes:
        for observation, action in episode.decisions():
            group = counts.setdefault(_group(player_sum(observation)), [0, 0])
            group[0] += int(action) == HIT
            group[1] += 1
    order = sorted(counts, key=lambda label: -1 if label == "sum<=11" else int(label.split("=")[1]))
    return {label: (counts[label][0], counts[label][1]) for label in order}
