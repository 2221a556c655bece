"""The second lab: frozen_lake() on both lakes, episodes replayed, answers against exact DP."""

from grader.grading.plugin import GradeCase, ProblemCase
from grader.lab.rl2.editions import V2024

PROBLEM = V2024.registry.acceptance_problem(__name__)


def test_frozen_lake(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
