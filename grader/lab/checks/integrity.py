"""Trusted views of the episodes a call played, and the integrity diagnoses every check shares."""

from __future__ import annotations

import functools
from collections import Counter
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from grader.lab.checks.base import RESET_SLACK, CallRecord, Verdict
from grader.lab.checks.episodes import Episode, all_resets, episodes_per_call, played_episodes
from grader.lab.checks.starts import selection_problem
from grader.sandbox.limits import CallBudget
from grader.sandbox.replay import not_replayed, replay_episodes, verify_reset_seeds

if TYPE_CHECKING:
    from grader.lab.games import GameRules
    from grader.lab.settings import PlayedProblemConfig
    from grader.sandbox.episode_log import EpisodeLog
    from grader.sandbox.outcome import CallOutcome

__all__ = [
    "Episode",
    "all_resets",
    "episodes_per_call",
    "games_budget",
    "integrity_problem",
    "played_episodes",
    "repeated_seed_problem",
    "replay_call",
    "settled_by",
]


def games_budget(games: int, steps_per_game: int) -> CallBudget:
    """What a call that plays `games` games of at most `steps_per_game` steps each may record.

    Twice the games in resets plus `RESET_SLACK` (room for an extra reset per game, judged by the
    selection test of `grader.lab.checks.starts`, not cut off), and the steps of the games plus
    `RESET_SLACK` games' worth. Beyond it the child stops recording and the call is `failed` with a
    description of what it played (`outcome_verdict`), so the grader never replays more than this.
    """
    return CallBudget(2 * games + RESET_SLACK, (games + RESET_SLACK) * steps_per_game)


NO_EPISODES = CallBudget(0, 0)
"""The budget of a call that records no episodes."""


def settled_by(record: CallRecord, rules: GameRules | None) -> str | None:
    """Why a problem's verdict can no longer change after this call, or None.

    A call that did not return normally scores the problem 0 (`outcome_verdict`); episodes that are not
    the problem's game and resets with options fail it (`integrity_problem`). Either way more calls
    cannot change the verdict and are not made. (Unplayed resets are judged over all calls together by
    the selection test, `grader.lab.checks.starts`.)
    """
    status = record.outcome.status.value
    if status == "timeout":
        return "it did not return in time"
    if status != "ok":
        return f"it ended with {status.replace('_', ' ')}"
    if _replay_refusal(record.outcome.episodes, rules) is not None:
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
    environments = {(log.requested_id, log.environment): log for log in logs}
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
    ``options``; the played starts are not a fair sample of the dealt ones (`selection_problem`: unplayed
    resets alone are harmless); the replay disagrees with the student's log; an episode was abandoned
    before it ended (reset in the middle of a game, or stopped early). Steps after an episode ended are
    not a problem here: every check judges each game up to its end, so they change nothing counted
    unless the returned result counted them (then it disagrees with the replay and fails there);
    `post_terminal_note` describes them.
    """
    altered = seed_problem(records)
    if altered:
        return altered
    refused = _replay_refusal([episode.log for episode in all_resets(records)], rules)
    if refused:
        return refused
    selected = selection_problem(records)
    if selected:
        return selected
    for episode in episodes:
        if episode.replay.mismatch:
            return (
                f"episode {_where(episode)} did not replay: {episode.replay.mismatch}. "
                "The grader replays every episode in its own environment; "
                "results that the real game does not produce cannot count"
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


def post_terminal_note(episodes: Sequence[Episode], deduction: float = 0.0) -> str:
    """The feedback sentence on steps taken after games had ended ("" when there were none).

    Such steps change nothing the grader counts: each game is judged up to its end (its decisions, its
    result), and a returned result that counted them disagrees with the replay and fails on that.
    """
    after_done = [episode for episode in episodes if episode.replay.steps_after_done > 0]
    if not after_done:
        return ""
    first = after_done[0]
    steps = sum(episode.replay.steps_after_done for episode in after_done)
    cost = f" ({deduction:.0%} of the points deducted)" if deduction else ""
    return (
        f" Note: {len(after_done)} game(s) kept stepping after the game was over ({steps} step(s) in all; e.g. episode {_where(first)} ended after {first.length} steps and {first.replay.steps_after_done} more followed). "  # noqa: E501
        f"Those steps change nothing counted here: every game is judged up to its end{cost}. "
        "Stop stepping as soon as `done` (terminated or truncated) is True."
    )


JudgeT = Callable[[Any, Any, Sequence[CallRecord]], Verdict]


def noting_post_terminal_steps(judge: JudgeT) -> JudgeT:
    """Add `post_terminal_note` to a passing verdict, less the configured `post_terminal_steps_deduction`."""

    @functools.wraps(judge)
    def noted(check: Any, settings: PlayedProblemConfig, records: Sequence[CallRecord]) -> Verdict:
        verdict = judge(check, settings, records)
        if verdict.status != "passed":
            return verdict
        deduction = settings.post_terminal_steps_deduction
        episodes = played_episodes(records)
        note = post_terminal_note(episodes, deduction)
        if not note:
            return verdict
        steps = sum(episode.replay.steps_after_done for episode in episodes)
        return Verdict(
            verdict.status,
            max(verdict.fraction - deduction, 0.0),
            verdict.feedback + note,
            {**verdict.measurements, "steps_after_done": steps},
        )

    return noted


def played_games_problem(
    records: Sequence[CallRecord], episodes: Sequence[Episode], rules: GameRules, *, across_calls: bool
) -> str | None:
    """`integrity_problem`, then `repeated_seed_problem` over every reset (played or not), or None.

    Args:
        records: The problem's call records.
        episodes: Their played episodes (`played_episodes`).
        rules: The games the episodes must be played in.
        across_calls: Count repeated seeds over all calls (True) or within each call only (False).
    """
    return integrity_problem(records, episodes, rules) or repeated_seed_problem(
        all_resets(records), across_calls=across_calls
    )


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
