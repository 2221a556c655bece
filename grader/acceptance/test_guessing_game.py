"""Optional: guessing_game() bisects to the target; every returned count is its replayed game's guesses."""

from grader.plugin import GradeCase, ProblemCase
from grader.problems import ProblemId

PROBLEM: ProblemId = "guessing_game"


def test_guessing_game(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
