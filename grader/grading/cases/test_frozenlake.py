"""The second lab (2018): frozenlake() on both lakes, its episodes replayed, its answers against exact DP."""

from grader.grading.plugin import GradeCase, ProblemCase
from grader.lab.rl2.editions import V2018

PROBLEM = V2018.registry.acceptance_problem(__name__)


def test_frozenlake(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
