"""Problem 3: `cartpole()` balances CartPole-v0 with the pole tip's velocity and returns the steps lasted."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from grader.checks.base import CallRecord, ProblemId, Verdict, paused_gc
from grader.checks.integrity import games_budget
from grader.checks.lengths import judge_lengths
from grader.config import CartpoleConfig, ProblemConfig
from grader.errors import PlanError
from grader.games import allowed_games
from grader.sandbox.outcome import Call, FunctionInfo

EPISODE_STEPS = 1_000
"""Steps recorded per game: CartPole-v0 ends at 200 (v1 at 500); room for steps after the end."""


def _settings(config: ProblemConfig) -> CartpoleConfig:
    if not isinstance(config, CartpoleConfig):
        raise PlanError(f"expected the cartpole settings, found {type(config).__name__}")
    return config


@dataclass
class CartpoleCheck:
    """cartpole() called many times: each return is its replayed episode's length; the lab's bar holds."""

    id: ProblemId = "cartpole"
    title: str = "Problem 3: CartPole"

    def plan(self, config: ProblemConfig, functions: Mapping[str, FunctionInfo]) -> list[Call]:
        """The configured number of cartpole() calls."""
        budget = games_budget(1, EPISODE_STEPS)
        return [Call("cartpole", budget=budget) for _ in range(_settings(config).calls)]

    @paused_gc
    def judge(self, config: ProblemConfig, records: Sequence[CallRecord]) -> Verdict:
        """Judge the returned lengths against the replays, then mean and minimum against the bar."""
        settings = _settings(config)
        runs = judge_lengths("cartpole", allowed_games(self.id, settings.accepted_envs), records)
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
        fraction = 1.0 - (settings.uncounted_steps_deduction if runs.uncounted_steps else 0.0)
        return Verdict("passed", fraction, f"cartpole(): {measured}; {bar}.{note}", measurements)
