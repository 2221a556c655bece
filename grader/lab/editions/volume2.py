"""Edition 3, "Volume 2: Gymnasium" (about 2023-2024): render flags, gymnasium, the same problems."""

from grader.lab.editions.pack import BUNDLED_CONFIG, REPOSITORY, Edition, ExpectedFunction
from grader.lab.problems import PROBLEMS

FUNCTIONS = (
    ExpectedFunction("random_blackjack", ("n",), env_ids=("Blackjack-v1",)),
    ExpectedFunction("blackjack", ("n=11",), env_ids=("Blackjack-v1",)),
    ExpectedFunction("cartpole", ("render=False",), env_ids=("CartPole-v1",)),
    ExpectedFunction("car", ("render=False",), env_ids=("MountainCar-v0",)),
    ExpectedFunction(
        "find_qvalues", ("env", "alpha=.1", "gamma=.6", "epsilon=.1"), provided=True, env_ids=("Taxi-v3",)
    ),
    ExpectedFunction("taxi", ("q_table",), env_ids=("Taxi-v3",)),
)

VOLUME2 = Edition(
    name="volume2",
    number=3,
    title="Volume 2: Gymnasium",
    api="gymnasium",
    registry=PROBLEMS,
    functions=FUNCTIONS,
    template=REPOSITORY / "submissions" / "templates" / "volume2.py",
    reference=REPOSITORY / "submissions" / "gymnasium_complete.py",
    default_config=BUNDLED_CONFIG,
    notebook_name="gymnasium.ipynb",
)
"""Graded like the first edition: cartpole() and car() are called without arguments, so `render` keeps its
default False (no window is ever asked for); taxi(q_table)'s 1 000 runs are judged by their replays."""
