"""Trusted views of the episodes a call played, and the integrity diagnoses every check shares."""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from grader.checks.base import CallRecord
from grader.sandbox.outcome import CallBudget
from grader.sandbox.replay import not_replayed, replay_episodes, verify_reset_seeds

if TYPE_CHECKING:
    from grader.games import GameRules
    from grader.sandbox.episode_log import EpisodeLog
    from grader.sandbox.outcome import CallOutcome
    from grader.sandbox.replay import Replay

RESET_SLACK = 8
"""Resets beyond the planned games a call may record, so that extra resets get a diagnosis, not a cut-off."""


@dataclass(slots=True)
class Episode:
    """One played episode: the student's actions with the outcome the grader's own replay produced.

    Attributes:
        call_index: Index of the call (in planned order) that played it.
        position: Index of the episode among the call's played episodes.
        log: The student's log (untrusted: only actions, ids and seeds are read from it).
        replay: The grader's replay of those actions.
    """

    call_index: int
    position: int
    log: EpisodeLog
    replay: Replay

    @property
    def length(self) -> int:
        """Steps until the episode ended (or all steps, when it never ended)."""
        return int(self.replay.length)

    @property
    def finished(self) -> bool:
        """Whether the episode reached a terminal state or its time limit."""
        last = self.length - 1
        return last >= 0 and bool(self.replay.terminated[last] or self.replay.truncated[last])

    @property
    def reached_terminal(self) -> bool:
        """Whether the episode ended in a terminal state (not by the time limit)."""
        last = self.length - 1
        return last >= 0 and bool(self.replay.terminated[last])

    @property
    def actions(self) -> list[Any]:
        """The actions taken before the episode ended."""
        return list(self.log.actions[: self.length])

    @property
    def rewards(self) -> list[float]:
        """The replayed rewards of the steps before the episode ended."""
        return [float(reward) for reward in self.replay.rewards[: self.length]]

    @property
    def total_reward(self) -> float:
        """Sum of the replayed rewards."""
        return float(self.replay.total_reward)

    @property
    def final_reward(self) -> float:
        """The replayed reward of the last step (0 for an empty episode)."""
        rewards = self.rewards
        return rewards[-1] if rewards else 0.0

    def decisions(self) -> list[tuple[Any, Any]]:
        """(observation seen, action taken) for every step before the episode ended."""
        length = self.replay.length
        return list(zip(self.replay.observations[:length], self.log.actions[:length], strict=True))


def played_episodes(records: Sequence[CallRecord]) -> list[Episode]:
    """Every episode of the records in which at least one action was taken, in play order."""
    episodes = []
    for call_index, record in enumerate(records):
        played = [
            (log, replay)
            for log, replay in zip(record.outcome.episodes, record.replays, strict=True)
            if len(log.actions) > 0
        ]
        episodes += [
            Episode(call_index, position, log, replay) for position, (log, replay) in enumerate(played)
        ]
    return episodes


def episodes_per_call(records: Sequence[CallRecord], episodes: Sequence[Episode]) -> list[list[Episode]]:
    """The played episodes (from `played_episodes(records)`) grouped by call."""
    grouped: list[list[Episode]] = [[] for _ in records]
    for episode in episodes:
        grouped[episode.call_index].append(episode)
    return grouped


def all_resets(records: Sequence[CallRecord]) -> list[Episode]:
    """Every reset of the records, played or not, in reset order (``position``: index among the call's)."""
    return [
        Episode(call_index, position, log, replay)
        for call_index, record in enumerate(records)
        for position, (log, replay) in enumerate(zip(record.outcome.episodes, record.replays, strict=True))
    ]


def games_budget(games: int, steps_per_game: int) -> CallBudget:
    """What a call that plays `games` games of at most `steps_per_game` steps each may record.

    Twice the games in resets (every unplayed reset is then diagnosed by `scouting_problem`, not cut
    off), and the steps of the games plus a few more (`RESET_SLACK`). Beyond it the child stops recording
    and the call fails, so the grader never replays more than this.
    """
    return CallBudget(2 * games + RESET_SLACK, (games + RESET_SLACK) * steps_per_game)


NO_EPISODES = CallBudget(0, 0)
"""The budget of a call that records no episodes."""


def settled_by(record: CallRecord, rules: GameRules | None) -> str | None:
    """Why a problem's verdict can no longer change after this call, or None.

    A call that did not return normally scores the problem 0 (`outcome_verdict`); episodes that are not
    the problem's game, resets with options and unplayed resets fail it (`integrity_problem`). Either way
    more calls cannot change the verdict and are not made.
    """
    status = record.outcome.status.value
    if status == "timeout":
        return "it did not return in time"
    if status != "ok":
        return f"it ended with {status.replace('_', ' ')}"
    if _replay_refusal(record.outcome.episodes, rules) is not None or scouting_problem([record]) is not None:
        return "it broke a rule of the game"
    return None


def replay_call(outcome: CallOutcome, rules: GameRules | None) -> CallRecord:
    """A call's record: its logs replayed, unless they may not be (then none is, and each says why).

    Whether an episode may be replayed is decided from the log before any env is built: its env id and
    arguments must be the problem's game (`rules`; None: the problem plays no episodes) and its reset
    must have no ``options``. Nothing else the student passed reaches an env constructor here.
    """
    logs = outcome.episodes
    refusal = _replay_refusal(logs, rules)
    if refusal is not None:
        return CallRecord(outcome, [not_replayed(refusal)] * len(logs))
    return CallRecord(outcome, replay_episodes(logs))


def _replay_refusal(logs: Sequence[EpisodeLog], rules: GameRules | None) -> str | None:
    if not logs:
        return None
    if rules is None:
        return f"this problem plays no episodes, but the call logged {len(logs)}"
    environments = {(log.env_id, log.requested_id, repr(sorted(log.env_kwargs.items()))): log for log in logs}
    for log in environments.values():
        problem = rules.problem_with(log)
        if problem:
            return problem
    return options_problem(logs)


def options_problem(logs: Sequence[EpisodeLog]) -> str | None:
    """Why resets that passed ``options`` cannot count, or None when none did."""
    chosen = [number for number, log in enumerate(logs) if log.reset_options]
    if not chosen:
        return None
    options = logs[chosen[0]].reset_options or {}
    shown = ", ".join(f"{name!r}: {value!r}" for name, value in list(options.items())[:4])[:200]
    return (
        f"{len(chosen)} reset(s) passed options (e.g. reset {chosen[0] + 1}: options={{{shown}}}), which choose the start of the game instead of letting the environment deal it. "  # noqa: E501
        "Every start must be the grader's: call reset() without options"
    )


def scouting_problem(records: Sequence[CallRecord]) -> str | None:
    """Why some call reset an environment without playing the game it dealt, or None.

    Every reset deals a game the grader counts. A reset that is not played abandons that game; resetting
    until the start looks easy and playing only that one ("scouting") would choose the starts the
    statistics rely on. The lab's code needs no such reset, so per environment a call may only leave
    unplayed its first reset when another reset of that environment follows (the reset right after
    ``gym.make``, or the one the classic API needed before the first step) and its last reset when an
    earlier one was played (a reset at the end of the game loop).
    """
    for call_index, record in enumerate(records):
        resets: dict[int, list[int]] = {}
        for position, log in enumerate(record.outcome.episodes):
            resets.setdefault(log.env_index, []).append(position)
        unplayed = [
            position
            for positions in resets.values()
            for order, position in enumerate(positions)
            if not _tolerated_unplayed(record.outcome.episodes, positions, order)
        ]
        if unplayed:
            total = len(record.outcome.episodes)
            shown = ", ".join(str(position + 1) for position in unplayed[:5])
            more = ", ..." if len(unplayed) > 5 else ""
            return (
                f"call {call_index + 1} reset its environment {total} times and left {len(unplayed)} of those games unplayed (resets {shown}{more} took no step before the next reset): "  # noqa: E501
                "every reset deals a game that counts, and resetting until the start looks easy chooses the games. "  # noqa: E501
                "Reset once per game and play every game you reset until `done` is True"
            )
    return None


def _tolerated_unplayed(logs: Sequence[EpisodeLog], positions: list[int], order: int) -> bool:
    if logs[positions[order]].steps > 0:
        return True
    first_then_more = order == 0 and len(positions) > 1
    last_after_played = order == len(positions) - 1 and any(logs[p].steps > 0 for p in positions[:order])
    return first_then_more or last_after_played


def seed_problem(records: Sequence[CallRecord]) -> str | None:
    """Why some call's episodes did not start from the seeds the grader's stream prescribes, or None."""
    for record in records:
        deviation = verify_reset_seeds(record.outcome.episodes, record.outcome.seed)
        if deviation:
            return deviation
    return None


def integrity_problem(
    records: Sequence[CallRecord], episodes: Sequence[Episode], rules: GameRules
) -> str | None:
    """The first reason the episodes cannot be trusted or are not the lab's game, or None.

    Checks every reset, played or not, in order: a reset seed differs from the grader's stream (an
    altered log); the environment or its arguments differ from the lab's game; a reset passed
    ``options``; a reset was left unplayed (`scouting_problem`); the replay disagrees with the student's
    log; steps were taken after an episode ended; an episode was abandoned before it ended (reset in the
    middle of a game, or stopped early).
    """
    altered = seed_problem(records)
    if altered:
        return altered
    refused = _replay_refusal([episode.log for episode in all_resets(records)], rules)
    if refused:
        return refused
    scouted = scouting_problem(records)
    if scouted:
        return scouted
    for episode in episodes:
        if episode.replay.mismatch:
            return (
                f"episode {_where(episode)} did not replay: {episode.replay.mismatch}. "
                "The grader replays every episode in its own environment; "
                "results that the real game does not produce cannot count"
            )
    after_done = [episode for episode in episodes if episode.replay.steps_after_done > 0]
    if after_done:
        first = after_done[0]
        return (
            f"{len(after_done)} episode(s) kept stepping after the game was over (e.g. episode {_where(first)} ended after {first.length} steps and you took {first.replay.steps_after_done} more). "  # noqa: E501
            "Stop as soon as `done` (terminated or truncated) is True"
        )
    unfinished = [episode for episode in episodes if not episode.finished]
    if unfinished:
        first = unfinished[0]
        return (
            f"{len(unfinished)} game(s) were abandoned before they ended (e.g. episode {_where(first)} stopped after {first.length} steps without terminating): "  # noqa: E501
            "you reset (or stopped) in the middle of a game. "
            "Play each game until `done` is True and reset only between games"
        )
    return None


def repeated_seed_problem(episodes: Sequence[Episode], *, across_calls: bool) -> str | None:
    """A diagnosis when several episodes were reset with the same seed of the student's, or None.

    Episodes reset with the same seed are the same game, so their results are not independent runs.
    Within one call this is always wrong; across calls it is wrong for problems whose function plays one
    episode per call (the lab calls them 100 times to average independent runs).

    Args:
        episodes: The problem's played episodes.
        across_calls: Count repeats over all calls (True) or within each call only (False).
    """
    seeds = Counter(
        (0 if across_calls else episode.call_index, episode.log.student_seed)
        for episode in episodes
        if episode.log.student_seed is not None
    )
    repeated = [(key, count) for key, count in seeds.items() if count > 1]
    if not repeated:
        return None
    (_, seed), count = max(repeated, key=lambda item: item[1])
    return (
        f"{count} episodes were reset with the same seed ({seed}), so outside the grader they are the same game played {count} times and their average says nothing: "  # noqa: E501
        "the runs are not independent. Call reset() without a seed (or seed only the first reset)"
    )


def _where(episode: Episode) -> str:
    return f"{episode.position + 1} of call {episode.call_index + 1}"
