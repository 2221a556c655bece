"""Whether the games a call played are a fair sample of the starts its resets dealt (the selection test).

Every reset deals a start from the grader's seed stream, and the grader can tell how good each start is
without the student's help: exactly for Blackjack (the threshold player's win probability from that hand,
`reference.oracles`) and Taxi (the optimal value of the start state), by the reference policy's outcome for
CartPole and MountainCar (the steps it lasts or takes from that start), plus what a student's code could
look at in the start (its coordinates, their sizes). A reset left unplayed is harmless unless the choice
of which starts to play looked at them ("scouting": reset until the start looks easy, then play it).

The test. Each played game forms a group with the unplayed resets dealt since the previous played game
(unplayed resets after a call's last game join its last group). In a group of k >= 2 starts, u is the
played start's mid-rank among them scaled to [0, 1] (0: worst, 1: best, ties counted half). When the
choice of which reset to play does not depend on the starts (an extra `env.reset()` before playing, a
reset at the end of the loop), the starts are i.i.d. draws of the grader's stream, every position is
equally likely to hold each rank, and u has mean 1/2 whatever k and whatever ties; groups are independent.
Hoeffding's inequality bounds the two-sided tail of S = sum(u - 1/2) over n groups without any
approximation: P(|S| >= t) <= 2 exp(-2 t^2 / n). Each feature is tested at `SELECTION_ALPHA` / (number of
features) (Bonferroni), so an honest submission fails this rule with probability at most `SELECTION_ALPHA`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np

from grader.lab.checks.base import CallRecord
from grader.lab.checks.episodes import Episode, all_resets
from grader.lab.games import default_kwargs
from grader.sandbox.replay import policy_rollout_steps
from reference.oracles import optimal_q_table, threshold_start_outcome
from reference.solutions import cartpole_policy, mountain_car_policy

SELECTION_ALPHA = 1e-6
"""Largest probability that the selection test fails a submission whose choice of starts ignores them."""
BLACKJACK_REFERENCE_THRESHOLD = 13
"""The threshold player that values a Blackjack start (the exact best n of the lab's game)."""
TAXI_GAMMA = 0.6
"""The discount of the optimal Q-table that values a Taxi start (the lab's gamma)."""
REFERENCE_STEP_LIMIT = 1_000
"""Most steps of a reference rollout from a start (CartPole and MountainCar end by 500)."""


@dataclass(frozen=True)
class Feature:
    """One way to value a start: its name for the feedback and which direction is easier."""

    name: str
    value: Callable[[Episode], float]
    higher_is: str
    lower_is: str
    costly: bool = False
    """Valued by rolling the reference policy out from the start: computed after the cheap features."""


@dataclass(frozen=True)
class StartGroup:
    """A played game and the unplayed resets attributed to it (dealt since the previous played game)."""

    played: Episode
    unplayed: list[Episode]


@dataclass(frozen=True)
class SelectionTest:
    """The result of the selection test on one feature.

    Attributes:
        feature: The feature's name.
        groups: Groups with at least one unplayed start (the only ones that say anything).
        statistic: S = sum of (u - 1/2) over those groups.
        p_value: Hoeffding's bound on P(|S| >= observed) for a choice that ignores the starts.
        threshold: The p-value at or below which the test fails (`SELECTION_ALPHA` / features).
    """

    feature: str
    groups: int
    statistic: float
    p_value: float
    threshold: float

    @property
    def fails(self) -> bool:
        """Whether the played starts are too far from a fair sample."""
        return self.p_value <= self.threshold


def start_groups(records: Sequence[CallRecord]) -> list[StartGroup]:
    """Every played game with the unplayed resets dealt before it (and, for a call's last game, after it)."""
    groups: list[StartGroup] = []
    by_call: dict[int, list[Episode]] = {}
    for reset in all_resets(records):
        by_call.setdefault(reset.call_index, []).append(reset)
    for resets in by_call.values():
        pending: list[Episode] = []
        call_groups: list[StartGroup] = []
        for reset in resets:
            if len(reset.log.actions) > 0:
                call_groups.append(StartGroup(reset, pending))
                pending = []
            else:
                pending.append(reset)
        if call_groups and pending:
            last = call_groups[-1]
            call_groups[-1] = StartGroup(last.played, last.unplayed + pending)
        groups += call_groups
    return groups


def selection_tests(
    records: Sequence[CallRecord], alpha: float = SELECTION_ALPHA, *, until_failure: bool = False
) -> list[SelectionTest]:
    """The selection test on every feature of the game played (none when no reset went unplayed).

    With ``until_failure`` the cheap features are tested first and testing stops at the first that fails:
    the rule's decision (fail when any feature fails, each at its Bonferroni share of ``alpha``) is the same,
    but a scouting call does not make the grader roll the reference policy out from every start it dealt.
    """
    groups = [group for group in start_groups(records) if group.unplayed]
    if not groups:
        return []
    features = features_of(groups[0].played.log.env_id)
    ordered = sorted(features, key=lambda feature: feature.costly) if until_failure else features
    tests: list[SelectionTest] = []
    for feature in ordered:
        if until_failure and any(test.fails for test in tests):
            break
        scaled = [_scaled_rank(feature.value, group) for group in groups]
        if any(u is None for u in scaled):
            continue
        statistic = math.fsum(u - 0.5 for u in scaled if u is not None)
        tests.append(
            SelectionTest(
                feature.name,
                len(groups),
                statistic,
                hoeffding_p_value(statistic, len(groups)),
                alpha / len(features),
            )
        )
    return tests


def selection_problem(records: Sequence[CallRecord], alpha: float = SELECTION_ALPHA) -> str | None:
    """Why the played starts are not a fair sample of the dealt ones (`selection_tests`), or None."""
    tests = selection_tests(records, alpha, until_failure=True)
    failing = [test for test in tests if test.fails]
    if not failing:
        return None
    worst = min(failing, key=lambda test: test.p_value)
    feature = next(f for f in features_of(_first_env(records)) if f.name == worst.feature)
    direction = feature.higher_is if worst.statistic > 0 else feature.lower_is
    unplayed = sum(len(group.unplayed) for group in start_groups(records))
    share = 0.5 + worst.statistic / worst.groups
    return (
        f"{unplayed} reset(s) were left unplayed, and the starts that were played are not a fair sample of the starts dealt: "  # noqa: E501
        f"in {worst.groups} games that had unplayed resets beside them, the played start ranked on average at {share:.2f} of its group by {worst.feature} (0.50 when the choice ignores the starts: yours played the {direction}), which a choice that ignores the starts produces with probability at most {worst.p_value:.1e}. "  # noqa: E501
        "Every reset deals a game that counts, and choosing which start to play by looking at it chooses the games. "  # noqa: E501
        "Reset once per game and play every game you reset"
    )


def hoeffding_p_value(statistic: float, groups: int) -> float:
    """Hoeffding's two-sided bound for a sum of `groups` independent [0, 1] terms centred at their mean.

    Written by hand: the bound is one line and no kept library offers it (it is not a distribution).
    """
    if groups == 0:
        return 1.0
    return min(1.0, 2.0 * math.exp(-2.0 * statistic * statistic / groups))


def _scaled_rank(value: Callable[[Episode], float], group: StartGroup) -> float | None:
    try:
        played = value(group.played)
        others = [value(episode) for episode in group.unplayed]
    except (IndexError, TypeError, ValueError):  # a start the replay could not deal: no rank
        return None
    below = sum(1 for other in others if other < played)
    tied = sum(1 for other in others if other == played)
    return (below + 0.5 * tied) / len(others)


def _first_env(records: Sequence[CallRecord]) -> str:
    return next(episode.log.env_id for episode in all_resets(records))


def features_of(env_id: str) -> list[Feature]:
    """The features that value a start of the gymnasium env `env_id` (none for other envs)."""
    if env_id.startswith("Blackjack"):
        return [
            Feature(
                "the threshold player's exact win probability", _blackjack_win, "easier hands", "harder hands"
            ),
            Feature(
                "the player's sum", lambda episode: float(_start(episode)[0]), "higher sums", "lower sums"
            ),
            Feature(
                "the dealer's card",
                lambda episode: float(_start(episode)[1]),
                "higher dealer cards",
                "lower dealer cards",
            ),
        ]
    if env_id.startswith("Taxi"):
        return [Feature("the optimal value of the start", _taxi_value, "easier starts", "harder starts")]
    if env_id.startswith("CartPole"):
        coordinates = ["cart position", "cart velocity", "pole angle", "pole angular velocity"]
        return [
            Feature(
                "the steps the reference policy lasts from it",
                _cartpole_steps,
                "easier starts",
                "harder starts",
                costly=True,
            ),
            Feature(
                "the size of the start's deviation from rest",
                _size,
                "larger deviations",
                "smaller deviations",
            ),
            *(
                Feature(
                    f"the size of the start's {name}",
                    _magnitude(index),
                    f"larger {name}s",
                    f"smaller {name}s",
                )
                for index, name in enumerate(coordinates)
            ),
        ]
    if env_id.startswith("MountainCar"):
        return [
            Feature(
                "the steps the reference policy takes from it",
                _car_steps,
                "harder starts",
                "easier starts",
                costly=True,
            ),
            Feature("the start position", _coordinate(0), "starts further right", "starts further left"),
        ]
    return []


def _start(episode: Episode) -> Any:
    return episode.replay.observations[0]


def _coordinate(index: int) -> Callable[[Episode], float]:
    return lambda episode: float(np.asarray(_start(episode), dtype=np.float64).reshape(-1)[index])


def _magnitude(index: int) -> Callable[[Episode], float]:
    return lambda episode: abs(_coordinate(index)(episode))


def _size(episode: Episode) -> float:
    return float(np.linalg.norm(np.asarray(_start(episode), dtype=np.float64)))


def _blackjack_win(episode: Episode) -> float:
    observation = tuple(int(part) for part in _start(episode))
    sab = bool({**default_kwargs(episode.log.env_id), **dict(episode.log.env_kwargs)}.get("sab", False))
    return threshold_start_outcome(
        (observation[0], observation[1], bool(observation[2])), BLACKJACK_REFERENCE_THRESHOLD, sab=sab
    ).win


@cache
def _taxi_values() -> np.ndarray[Any, np.dtype[np.float64]]:
    values: np.ndarray[Any, np.dtype[np.float64]] = optimal_q_table(TAXI_GAMMA).max(axis=1)
    return values


def _taxi_value(episode: Episode) -> float:
    return float(_taxi_values()[int(_start(episode))])


def _cartpole_steps(episode: Episode) -> float:
    return float(_reference_steps(episode, cartpole_policy))


def _car_steps(episode: Episode) -> float:
    return float(_reference_steps(episode, mountain_car_policy))


def _reference_steps(episode: Episode, policy: Callable[[Any], int]) -> int:
    """Steps the reference policy plays from the episode's start (its reset seed, the grader's env)."""
    return policy_rollout_steps(episode.log, policy, REFERENCE_STEP_LIMIT)
