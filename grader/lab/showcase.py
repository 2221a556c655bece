"""Which of a student's episodes the report replays as an animation: the one they would most like to see.

Each problem with a replay names its rule in its declaration (`Problem.showcase`). CartPole: the shortest
episode (where the pole fell first); MountainCar: the longest (where the car took longest to reach the
flag, or never did); Taxi: the last episode of the first call that returned (with the lab's order, an
episode of the Q-table policy). Only episodes the trusted replay reproduced exactly, of the
problem's own games made without extra arguments, are kept: the animation is re-rendered from the reset
seed and the actions, so it shows what the grader judged.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from numbers import Integral

from grader.lab.checks.base import CallRecord
from grader.report import EpisodeReplay
from grader.sandbox import OutcomeStatus
from grader.sandbox.episode_log import EpisodeLog
from grader.sandbox.replay import Replay

MAX_REPLAY_STEPS = 500
"""Longest episode kept (CartPole-v1's limit); the lab's games stop at 200."""
IGNORED_KWARGS = frozenset({"render_mode"})


@dataclass(frozen=True)
class ShowcaseRule:
    """How a problem chooses the episode its report replays.

    Attributes:
        env_ids: The gymnasium ids an episode may have been played in.
        choose: Picks one of the clean episodes (each with its trusted replay).
        label: How the report names the chosen episode, given how many were clean.
        first_call_only: Only the first call that returned counts (its episodes are the ones the lab
            meant, e.g. Taxi's Q-table episodes last).
    """

    env_ids: frozenset[str]
    choose: Callable[[list[tuple[EpisodeLog, Replay]]], tuple[EpisodeLog, Replay]]
    label: Callable[[int], str]
    first_call_only: bool = False


def _shortest(episodes: list[tuple[EpisodeLog, Replay]]) -> tuple[EpisodeLog, Replay]:
    return min(episodes, key=lambda episode: episode[1].length)


def _longest(episodes: list[tuple[EpisodeLog, Replay]]) -> tuple[EpisodeLog, Replay]:
    return max(episodes, key=lambda episode: episode[1].length)


def _last(episodes: list[tuple[EpisodeLog, Replay]]) -> tuple[EpisodeLog, Replay]:
    return episodes[-1]


SHORTEST_CARTPOLE = ShowcaseRule(
    frozenset({"CartPole-v0", "CartPole-v1"}),
    _shortest,
    lambda count: f"your shortest of {count} CartPole episodes",
)
LONGEST_MOUNTAIN_CAR = ShowcaseRule(
    frozenset({"MountainCar-v0"}),
    _longest,
    lambda count: f"your longest of {count} MountainCar episodes",
)
LAST_TAXI_OF_FIRST_CALL = ShowcaseRule(
    frozenset({"Taxi-v3", "Taxi-v4"}),
    _last,
    lambda count: (
        f"the last of the {count} Taxi episodes of your first call (the lab plays the Q-table's episodes last)"  # noqa: E501
    ),
    first_call_only=True,
)
"""The lab's replay rules (the problem declarations name them)."""


def showcase_episode(rule: ShowcaseRule | None, records: Sequence[CallRecord]) -> EpisodeReplay | None:
    """The episode the report animates under a problem's rule, or None (no rule, no clean episode).

    Args:
        rule: The problem's rule (`Problem.showcase`); None for a problem without a replay.
        records: The problem's calls with their trusted replays.

    Returns:
        The chosen episode, with its actions up to the replayed end.
    """
    if rule is None:
        return None
    if rule.first_call_only:
        records = [record for record in records if record.outcome.status == OutcomeStatus.OK][:1]
    episodes = [
        (log, replay)
        for record in records
        for log, replay in zip(record.outcome.episodes, record.replays, strict=False)
        if _clean(rule, log, replay)
    ]
    if not episodes:
        return None
    log, replay = rule.choose(episodes)
    return EpisodeReplay(
        label=rule.label(len(episodes)),
        env_id=log.env_id,
        reset_seed=log.reset_seed,
        actions=[int(action) for action in log.actions[: replay.length]],
        length=replay.length,
        total_reward=replay.total_reward,
    )


def _clean(rule: ShowcaseRule, log: EpisodeLog, replay: Replay) -> bool:
    return (
        log.env_id in rule.env_ids
        and not (set(log.env_kwargs) - IGNORED_KWARGS)
        and not log.reset_options
        and replay.matches
        and 0 < replay.length <= MAX_REPLAY_STEPS
        and _integral_actions(log.actions[: replay.length])
    )


def _integral_actions(actions: Sequence[object]) -> bool:
    """Every action an `Integral` that is no bool, decided once per type (Taxi: 2 million actions)."""
    return all(issubclass(kind, Integral) and not issubclass(kind, bool) for kind in set(map(type, actions)))
