"""The second lab: extract_policy() graded exactly on the grader's own MDPs (grader/lab/rl2/checks/)."""

from grader.grading.plugin import GradeCase, ProblemCase
from grader.lab.rl2.editions import V2018

PROBLEM = V2018.registry.acceptance_problem(__name__)


def test_extract_policy(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
