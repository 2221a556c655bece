"""The second lab: run_simulation() on the grader's envs and policies, each episode replayed."""

from grader.grading.plugin import GradeCase, ProblemCase
from grader.lab.rl2.editions import V2024

PROBLEM = V2024.registry.acceptance_problem(__name__)


def test_run_simulation(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
