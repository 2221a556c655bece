"""The problems of the OpenGym AI lab, declared once each, as the lab poses them, then the optional ones.

Everything that lists problems derives from `PROBLEMS`: the assignment configuration's tables
(`grader.lab.assignment`), `--only`, the acceptance modules (`grader/grading/cases/test_<id>.py`), the
report's titles and points, the games each problem accepts, the episode its report replays and its plot.
Adding a problem is one entry here (or in an edition pack), its module in `grader/lab/checks/` (settings model
+ check), its acceptance module and its `[problems.<id>]` table (ARCHITECTURE.md, "Adding an edition or a
lab"). This registry is the first edition's (`grader.lab.editions.classic`); later editions reuse its
declarations.
"""

from grader.lab.checks.blackjack import BlackjackCheck, BlackjackConfig
from grader.lab.checks.car import CarCheck, CarConfig
from grader.lab.checks.cartpole import CartpoleCheck, CartpoleConfig
from grader.lab.checks.find_qvalues import FindQvaluesCheck, FindQvaluesConfig
from grader.lab.checks.guessing_game import GuessingGameCheck, GuessingGameConfig
from grader.lab.checks.random_blackjack import RandomBlackjackCheck, RandomBlackjackConfig
from grader.lab.checks.taxi import TaxiCheck, TaxiConfig
from grader.lab.games import BLACKJACK_GAMES, CARTPOLE_GAMES, GUESSING_GAMES, MOUNTAIN_CAR_GAMES, TAXI_GAMES
from grader.lab.plots import plot_blackjack, plot_guess_counts, plot_lengths, plot_taxi
from grader.lab.registry import Problem, ProblemId, Registry
from grader.lab.showcase import LAST_TAXI_OF_FIRST_CALL, LONGEST_MOUNTAIN_CAR, SHORTEST_CARTPOLE

__all__ = ["PROBLEMS", "PROBLEM_IDS", "ProblemId", "problem"]

PROBLEMS = Registry(
    (
        Problem(
            id="random_blackjack",
            title="Problem 1: random Blackjack",
            points=1.0,
            config=RandomBlackjackConfig,
            check=RandomBlackjackCheck(),
            games=BLACKJACK_GAMES,
        ),
        Problem(
            id="blackjack",
            title="Problem 2: threshold Blackjack",
            points=1.0,
            config=BlackjackConfig,
            check=BlackjackCheck(),
            games=BLACKJACK_GAMES,
            plot=plot_blackjack,
        ),
        Problem(
            id="cartpole",
            title="Problem 3: CartPole",
            points=1.0,
            config=CartpoleConfig,
            check=CartpoleCheck(),
            games=CARTPOLE_GAMES,
            showcase=SHORTEST_CARTPOLE,
            plot=plot_lengths,
        ),
        Problem(
            id="car",
            title="Problem 4: MountainCar",
            points=1.0,
            config=CarConfig,
            check=CarCheck(),
            games=MOUNTAIN_CAR_GAMES,
            showcase=LONGEST_MOUNTAIN_CAR,
            plot=plot_lengths,
        ),
        Problem(
            id="taxi",
            title="Problem 5: Taxi",
            points=1.0,
            config=TaxiConfig,
            check=TaxiCheck(),
            games=TAXI_GAMES,
            showcase=LAST_TAXI_OF_FIRST_CALL,
            plot=plot_taxi,
        ),
        Problem(
            id="find_qvalues",
            title="find_qvalues (provided by the lab)",
            points=0.0,
            config=FindQvaluesConfig,
            check=FindQvaluesCheck(),
        ),
        Problem(
            id="guessing_game",
            title="Optional: GuessingGame",
            points=1.0,
            config=GuessingGameConfig,
            check=GuessingGameCheck(),
            games=GUESSING_GAMES,
            plot=plot_guess_counts,
            enabled=False,
        ),
    )
)
"""The lab's problems, then the optional ones (disabled by default); every list of problems follows it."""

PROBLEM_IDS: tuple[ProblemId, ...] = PROBLEMS.ids
problem = PROBLEMS.problem
