"""The problem identifiers of the lab, in the order the lab poses them, then the optional ones."""

from typing import Literal

ProblemId = Literal[
    "random_blackjack", "blackjack", "cartpole", "car", "taxi", "find_qvalues", "guessing_game"
]

PROBLEM_IDS: tuple[ProblemId, ...] = (
    "random_blackjack",
    "blackjack",
    "cartpole",
    "car",
    "taxi",
    "find_qvalues",
    "guessing_game",
)
