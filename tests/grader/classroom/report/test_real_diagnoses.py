"""The diagnosis key holds on the checks' own feedback: students with the same mistake share a diagnosis
whatever their numbers, and different mistakes never merge.

Each simulated mistake of ``grader.simulated_students.behaviours`` (the same mistakes as
submissions/mistakes/) is played by two students on different seeds, so every measured number in their
feedback differs, and judged by the real check on test-sized samples. Not statistical: the grouping is exact
text after the numbers are replaced, so the test cannot fail by chance (only by a check writing a
seed-dependent word).
"""

from __future__ import annotations

import inspect
import zlib
from functools import partial

import pytest

from grader.classroom.report import ClassEntry, class_summary
from grader.lab.assignment import load_config
from grader.lab.checks.base import ProblemId
from grader.lab.problems import PROBLEMS
from grader.report import ProblemResult
from grader.simulated_students.behaviours import MISTAKES, Behaviour
from grader.simulated_students.simulation import StudentFunction, function_infos, simulate_calls

from .support import report

TEST_SIZES: dict[str, dict[str, int]] = {
    "random_blackjack": {"games": 2000},
    "blackjack": {"games_per_call": 1000},
    "taxi": {"episodes_per_scenario": 200},
}
"""Samples smaller than the assignment's (as in tests/grader/lab/checks/support.py) so the test stays
quick."""
CHOSEN = (
    "blackjack_less_than",
    "blackjack_stale_hand",
    "random_blackjack_average_reward",
    "cartpole_same_seed",
    "cartpole_counted_from_one",
    "car_scouting",
    "taxi_v2",
)
"""One or two mistakes per problem, among them one whose feedback lists a varying number of numbers."""
VARYING = (
    "blackjack_less_than",
    "blackjack_stale_hand",
    "random_blackjack_average_reward",
    "cartpole_counted_from_one",
    "car_scouting",
)
"""Those whose feedback holds measured numbers (the others' feedback is the same text for every seed)."""


def _judged(behaviour: Behaviour, seed: int) -> ProblemResult:
    problem: ProblemId = behaviour.problem
    settings = load_config().problems[problem].model_copy(update=TEST_SIZES.get(problem, {}))

    def sized(function: StudentFunction) -> StudentFunction:
        parameters = inspect.signature(function).parameters
        if "games" in parameters and hasattr(settings, "games_per_call"):
            return partial(function, games=settings.games_per_call)
        if "episodes" in parameters and hasattr(settings, "episodes_per_scenario"):
            return partial(function, episodes=settings.episodes_per_scenario)
        return function

    functions = {name: sized(function) for name, function in behaviour.functions.items()}
    check = PROBLEMS.problem(problem).check
    verdict = check.judge(
        settings, simulate_calls(check.plan(settings, function_infos(functions), 0), functions, seed)
    )
    return ProblemResult(
        id=problem, title=problem, status=verdict.status, score=0.0, max_score=1.0, feedback=verdict.feedback
    )


@pytest.mark.slow
def test_students_with_the_same_mistake_share_one_diagnosis_and_no_two_mistakes_merge(
    request: pytest.FixtureRequest,
) -> None:
    base = zlib.crc32(request.node.nodeid.rpartition("/")[2].encode())  # its name, not its folder
    mistakes = [mistake for mistake in MISTAKES if mistake.name in CHOSEN]
    assert sorted(mistake.name for mistake in mistakes) == sorted(CHOSEN)
    entries = [
        ClassEntry(
            f"{mistake.name}/{student}", report=report(_judged(mistake, base + 7919 * student + index))
        )
        for index, mistake in enumerate(mistakes)
        for student in (1, 2)
    ]
    feedback = {entry.identity: entry.report.problems[0].feedback for entry in entries if entry.report}
    differing = sorted(name for name in CHOSEN if feedback[f"{name}/1"] != feedback[f"{name}/2"])
    assert differing == sorted(VARYING), "the two students' numbers differ, or the test proves nothing"
    groups = sorted(diagnosis["identities"] for diagnosis in class_summary(entries)["diagnoses"])
    assert groups == sorted([f"{name}/1", f"{name}/2"] for name in CHOSEN)
