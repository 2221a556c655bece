"""Problem 1: random_blackjack(n) wins as often as random play does, backed by its replayed games."""

from grader.grading.plugin import GradeCase, ProblemCase
from grader.lab.problems import PROBLEMS

PROBLEM = PROBLEMS.acceptance_problem(__name__)


def test_random_blackjack(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
