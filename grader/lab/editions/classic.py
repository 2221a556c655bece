"""Edition 1, "OpenGym AI" on classic gym (about 2019-2021): the lab text; the default edition."""

from grader.lab.editions.pack import BUNDLED_CONFIG, REPOSITORY, Edition, ExpectedFunction
from grader.lab.problems import PROBLEMS
from grader.report import FIRST_EDITION

FUNCTIONS = (
    ExpectedFunction("random_blackjack", ("n",), env_ids=("Blackjack-v0",)),
    ExpectedFunction("blackjack", ("n=11",), env_ids=("Blackjack-v0",)),
    ExpectedFunction("cartpole", (), env_ids=("CartPole-v0",)),
    ExpectedFunction("car", (), env_ids=("MountainCar-v0",)),
    ExpectedFunction(
        "find_qvalues", ("env", "alpha=.1", "gamma=.6", "epsilon=.1"), provided=True, env_ids=("Taxi-v3",)
    ),
    ExpectedFunction("taxi", ("q_table",), env_ids=("Taxi-v3",)),
)

CLASSIC = Edition(
    name=FIRST_EDITION,
    number=1,
    title="OpenGym AI (classic gym)",
    api="classic",
    registry=PROBLEMS,
    functions=FUNCTIONS,
    template=REPOSITORY / "submissions" / "template.py",
    reference=REPOSITORY / "submissions" / "classic_complete.py",
    default_config=BUNDLED_CONFIG,
    notebook_name="opengym.py",
)
"""The lab as first published: every existing configuration and report names it implicitly."""
