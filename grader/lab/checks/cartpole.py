"""Problem 3: `cartpole()` balances CartPole-v0 with the pole tip's velocity and returns the steps lasted."""

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
"""Steps recorded per game: CartPole-v0 ends at 200 (v1 at 500); room for steps after the end."""


class CartpoleConfig(CountedStepsConfig):
    """The settings of `cartpole()`."""

    calls: int = Field(ge=1, description="How many times cartpole() is called (one episode each).")
    min_mean_steps: float = Field(ge=0.0, description="The mean episode length must be at least this.")
    min_steps: int = Field(ge=0, description="Every episode must last at least this many steps.")


@dataclass(frozen=True)
class CartpoleCheck:
    """cartpole() called many times: each return is its replayed episode's length; the lab's bar holds."""

    def plan(self, settings: CartpoleConfig, functions: Mapping[str, FunctionInfo], seed: int) -> list[Call]:
        """The configured number of cartpole() calls."""
        return one_game_calls("cartpole", settings.calls, EPISODE_STEPS)

    @paused_gc
    @noting_post_terminal_steps
    def judge(self, settings: CartpoleConfig, records: Sequence[CallRecord]) -> Verdict:
        """Judge the returned lengths against the replays, then mean and minimum against the bar."""
        runs = judge_lengths("cartpole", settings.game_rules(), records)
        if isinstance(runs, Verdict):
            return runs
        measurements = runs.measurements()
        shortest = min(runs.lengths)
        bar = f"the lab asks for at least {settings.min_steps} steps in every run and about 180 on average (graded: mean >= {settings.min_mean_steps:g} and every run >= {settings.min_steps})"  # noqa: E501
        measured = f"your {len(runs.lengths)} replayed runs lasted {runs.mean:.1f} steps on average, the shortest {shortest} ({runs.game.description})"  # noqa: E501
        note = runs.counting_note("cartpole", settings.uncounted_steps_deduction)
        if runs.mean < settings.min_mean_steps or shortest < settings.min_steps:
            return Verdict(
                "failed",
                0.0,
                f"cartpole(): {bar}; {measured}. Push the cart the way the tip of the pole is moving: "
                f"action 1 (right) when the pole's angular velocity observation[3] is positive, else 0.{note}",  # noqa: E501
                measurements,
            )
        fraction = runs.passing_fraction(settings.uncounted_steps_deduction)
        return Verdict("passed", fraction, f"cartpole(): {measured}; {bar}.{note}", measurements)
