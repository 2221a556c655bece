"""Edition rl1, problem 5: epsilon_decay() returns the lab's linear decay exactly over a grid of arguments."""

from grader.grading.plugin import GradeCase, ProblemCase
from grader.lab.editions.rl1 import RL1

PROBLEM = RL1.registry.acceptance_problem(__name__)


def test_epsilon_decay(problem_case: ProblemCase, grade: GradeCase) -> None:
    result = grade(problem_case)
    assert result.id == PROBLEM
