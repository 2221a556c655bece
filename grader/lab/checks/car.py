"""Problem 4: `car()` drives MountainCar-v0 to the flag and returns the steps it took."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from pydantic import Field

from grader.lab.checks.base import CallRecord, Verdict, paused_gc
from grader.lab.checks.integrity import noting_post_terminal_steps
from grader.lab.checks.lengths import judge_lengths, one_game_calls
from grader.lab.settings import CountedStepsConfig
from grader.sandbox.outcome import Call, FunctionInfo

EPISODE_STEPS = 1_000
"""Steps recorded per game: MountainCar-v0 ends at 200; room for steps after the end to be diagnosed."""


class CarConfig(CountedStepsConfig):
    """The settings of `car()`."""

    calls: int = Field(ge=1, description="How many times car() is called (one episode each).")
    max_mean_steps: float = Field(gt=0.0, description="The mean episode length must be strictly below this.")


@dataclass(frozen=True)
class CarCheck:
    """car() called many times: each return is its replayed length, every run reaches the goal, mean < bar."""

    def plan(self, settings: CarConfig, functions: Mapping[str, FunctionInfo], seed: int) -> list[Call]:
        """The configured number of car() calls."""
        return one_game_calls("car", settings.calls, EPISODE_STEPS)

    @paused_gc
    @noting_post_terminal_steps
    def judge(self, settings: CarConfig, records: Sequence[CallRecord]) -> Verdict:
        """Judge the returned lengths against the replays, then the goal and the mean against the bar."""
        runs = judge_lengths("car", settings.game_rules(), records)
        if isinstance(runs, Verdict):
            return runs
        measurements = runs.measurements()
        note = runs.counting_note("car", settings.uncounted_steps_deduction)
        stuck = sum(1 for episode in runs.episodes if not episode.reached_terminal)
        measurements["runs_reaching_goal"] = len(runs.episodes) - stuck
        bar = f"the lab asks for every run to reach the flag in fewer than {settings.max_mean_steps:g} steps on average"  # noqa: E501
        measured = f"{len(runs.episodes) - stuck} of your {len(runs.episodes)} replayed runs reached the flag, taking {runs.mean:.1f} steps on average"  # noqa: E501
        if stuck:
            return Verdict(
                "failed",
                0.0,
                f"car(): {bar}; {measured}, and {stuck} ran out of time (200 steps) short of it. "
                f"Build momentum: push (action 2 right, 0 left) in the direction the car is already moving (observation[1]).{note}",  # noqa: E501
                measurements,
            )
        if runs.mean >= settings.max_mean_steps:
            return Verdict(
                "failed",
                0.0,
                f"car(): {bar}; {measured}. "
                f"Push in the direction of the velocity on every step to swing up faster.{note}",
                measurements,
            )
        fraction = runs.passing_fraction(settings.uncounted_steps_deduction)
        return Verdict("passed", fraction, f"car(): {measured}; {bar}.{note}", measurements)
