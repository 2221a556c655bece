"""The lab-provided find_qvalues(env): it trains, and its greedy policy's exact return is reported."""

from grader.grading.plugin import GradeCase, ProblemCase
from grader.lab.problems import PROBLEMS

PROBLEM = PROBLEMS.acceptance_problem(__name__)


def test_find_qvalues(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
