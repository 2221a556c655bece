"""The second lab (2024): model_comparison(), both means against their replayed episodes."""

from grader.grading.plugin import GradeCase, ProblemCase
from grader.lab.rl2.editions import V2024

PROBLEM = V2024.registry.acceptance_problem(__name__)


def test_model_comparison(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
