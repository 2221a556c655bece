"""Optional: guessing_game() bisects to the target; every returned count is its replayed game's guesses."""

from grader.grading.plugin import GradeCase, ProblemCase
from grader.lab.problems import PROBLEMS

PROBLEM = PROBLEMS.acceptance_problem(__name__)


def test_guessing_game(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
