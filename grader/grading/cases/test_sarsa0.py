"""Edition rl1, problem 7: sarsa0() returns the SARSA(0) table of the transitions it played."""

from grader.grading.plugin import GradeCase, ProblemCase
from grader.lab.editions.rl1 import RL1

PROBLEM = RL1.registry.acceptance_problem(__name__)


def test_sarsa0(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
