"""Problem 5: taxi() returns random and Q-table means matching their exact expectations."""

from grader.grading.plugin import GradeCase, ProblemCase
from grader.lab.problems import PROBLEMS

PROBLEM = PROBLEMS.acceptance_problem(__name__)


def test_taxi(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
