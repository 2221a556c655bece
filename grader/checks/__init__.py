"""Per-problem checks: what to call in the sandbox and how to judge the outcomes (pure, no I/O)."""

from collections.abc import Mapping

from grader.checks.base import ProblemCheck, ProblemId
from grader.checks.blackjack import BlackjackCheck
from grader.checks.car import CarCheck
from grader.checks.cartpole import CartpoleCheck
from grader.checks.find_qvalues import FindQvaluesCheck
from grader.checks.guessing_game import GuessingGameCheck
from grader.checks.random_blackjack import RandomBlackjackCheck
from grader.checks.taxi import TaxiCheck

CHECKS: Mapping[ProblemId, ProblemCheck] = {
    check.id: check
    for check in (
        RandomBlackjackCheck(),
        BlackjackCheck(),
        CartpoleCheck(),
        CarCheck(),
        TaxiCheck(),
        FindQvaluesCheck(),
        GuessingGameCheck(),
    )
}

__all__ = ["CHECKS"]
