"""The reference passes every problem and every typical mistake gets its status and diagnosis.

False-fail probability of each reference test: the sum of the configured alphas of its statistical
tests (random_blackjack 3e-6, blackjack 4e-6, taxi 3e-6; cartpole/car: see bench/RESULTS.md, < 1e-6).
"""

import pytest

from grader.lab.checks.base import ProblemId
from grader.simulated_students.behaviours import MISTAKES, REFERENCE, Behaviour

from .support import grade

pytestmark = pytest.mark.slow  # every simulated student of every problem, judged


@pytest.mark.parametrize("problem", list(REFERENCE), ids=str)
def test_reference_passes(problem: ProblemId, seed: int) -> None:
    verdict = grade(problem, REFERENCE[problem], seed)
    assert (verdict.status, verdict.fraction) == ("passed", 1.0), verdict.feedback


@pytest.mark.parametrize("mistake", MISTAKES, ids=lambda mistake: mistake.name)
def test_mistake_is_diagnosed(mistake: Behaviour, seed: int) -> None:
    verdict = grade(mistake.problem, mistake.functions, seed)
    assert verdict.status == mistake.status, verdict.feedback
    assert mistake.feedback in verdict.feedback
    assert verdict.fraction == (1.0 if mistake.status == "passed" else 0.0)
