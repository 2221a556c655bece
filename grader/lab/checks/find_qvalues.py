"""The lab-provided `find_qvalues(env)`: validate the returned Q-table and report its exact greedy return."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydantic import Field

from grader.lab.checks.base import CallRecord, Verdict, judged_when_all_returned, paused_gc
from grader.lab.checks.integrity import NO_EPISODES
from grader.lab.checks.values import describe
from grader.lab.settings import ProblemConfig
from grader.sandbox.outcome import Call, FunctionInfo
from reference.oracles import greedy_policy_return, optimal_return

TAXI_SHAPE = (500, 6)
NOT_RUN_FEEDBACK = (
    "Not run: find_qvalues is worth 0 points and no other check needs its table (taxi(q_table) receives the grader's exact optimal table), so it was not called and its training cost you no time. "  # noqa: E501
    'To have your table checked anyway, grade with an assignment configuration whose [problems.find_qvalues] has run = "always" (gymgrade check --config FILE).'  # noqa: E501
)


class FindQvaluesConfig(ProblemConfig):
    """The lab-provided `find_qvalues(env)`: reported, weight 0 by default."""

    env_id: str = Field(description="The environment id find_qvalues is called with (the lab's Taxi-v3).")
    run: Literal["when_scored", "always"] = Field(
        default="when_scored",
        description="'when_scored' (default) calls find_qvalues only when the problem is worth points (no other verdict needs it: "  # noqa: E501
        "taxi(q_table) receives the grader's exact table); "
        "'always' calls it for feedback on its table even at 0 points.",
    )

    @property
    def called(self) -> bool:
        """Whether find_qvalues is called: it is worth points, or the configuration asks for it."""
        return self.points > 0 or self.run == "always"


@dataclass(frozen=True)
class FindQvaluesCheck:
    """find_qvalues("Taxi-v3"): a finite (500, 6) table; its greedy policy's exact return is reported."""

    def plan(
        self, settings: FindQvaluesConfig, functions: Mapping[str, FunctionInfo], seed: int
    ) -> list[Call]:
        """One unrecorded call (100 000 training episodes are not worth logging), or none when not called.

        No verdict needs the table unless the problem is worth points (``taxi(q_table)`` gets the grader's
        exact table), so by default nothing is called and the student's training costs nothing.
        """
        if not settings.called:
            return []
        return [Call("find_qvalues", (settings.env_id,), record_episodes=False, budget=NO_EPISODES)]

    @paused_gc
    @judged_when_all_returned
    def judge(self, settings: FindQvaluesConfig, records: Sequence[CallRecord]) -> Verdict:
        """Validate the table and report the exact expected return of acting greedily on it."""
        if not settings.called:
            return Verdict("skipped", 0.0, NOT_RUN_FEEDBACK, {"calls_made": 0})
        value = records[0].outcome.value
        table = np.asarray(value) if isinstance(value, np.ndarray | list) else None
        if (
            table is None
            or table.shape != TAXI_SHAPE
            or table.dtype.kind not in "iuf"
            or not np.isfinite(table).all()
        ):
            found = (
                f"an array of shape {table.shape} and dtype {table.dtype}"
                if table is not None
                else describe(value)
            )
            return Verdict(
                "failed",
                0.0,
                f"find_qvalues('Taxi-v3') must return a finite {TAXI_SHAPE[0]} x {TAXI_SHAPE[1]} array of numbers (one row per state, one column per action); "  # noqa: E501
                f"it returned {found}.",
                {},
            )
        greedy = greedy_policy_return(table.astype(np.float64))
        optimal = optimal_return()
        return Verdict(
            "passed",
            1.0,
            f"Acting greedily on your table earns {greedy.mean:.3f} per Taxi episode on average (exact, over all start states); "  # noqa: E501
            f"the optimal policy earns {optimal.mean:.3f}.",
            {
                "greedy_mean_return": greedy.mean,
                "greedy_return_std": greedy.std,
                "optimal_mean_return": optimal.mean,
            },
        )
