"""Edition rl1, problem 7: compare() after the notebook's own cells ran, judged on its replayed episodes."""

from grader.editions.rl1 import RL1
from grader.plugin import GradeCase, ProblemCase

PROBLEM = RL1.registry.acceptance_problem(__name__)


def test_compare(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
