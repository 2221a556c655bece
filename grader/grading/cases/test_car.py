"""Problem 4: car() reaches the goal fast enough; every returned length is its replayed episode's."""

from grader.grading.plugin import GradeCase, ProblemCase
from grader.lab.problems import PROBLEMS

PROBLEM = PROBLEMS.acceptance_problem(__name__)


def test_car(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
