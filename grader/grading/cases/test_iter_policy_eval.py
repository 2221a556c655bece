"""The second lab: iter_policy_eval() graded exactly on the grader's own MDPs (grader/lab/rl2/checks/)."""

from grader.grading.plugin import GradeCase, ProblemCase
from grader.lab.rl2.editions import V2024

PROBLEM = V2024.registry.acceptance_problem(__name__)


def test_iter_policy_eval(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
