"""Edition rl1, problem 5: epsilon_decay() returns the lab's linear decay exactly over a grid of arguments."""

from grader.editions.rl1 import RL1
from grader.plugin import GradeCase, ProblemCase

PROBLEM = RL1.registry.acceptance_problem(__name__)


def test_epsilon_decay(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
