"""Edition rl1, problem 7: compare() on the grader's bound tables (or after the notebook's cells ran), judged
on its replayed episodes."""

from grader.grading.plugin import GradeCase, ProblemCase
from grader.lab.editions.rl1 import RL1

PROBLEM = RL1.registry.acceptance_problem(__name__)


def test_compare(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
