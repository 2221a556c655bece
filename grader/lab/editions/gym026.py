"""Edition 2, "OpenGym AI" as a gym 0.26 notebook (about 2022-2023): the same five functions."""

from grader.lab.editions.classic import FUNCTIONS as CLASSIC_FUNCTIONS
from grader.lab.editions.pack import BUNDLED_CONFIG, REPOSITORY, Edition, ExpectedFunction
from grader.lab.problems import PROBLEMS

_ENVS = {"random_blackjack": ("Blackjack-v1",), "blackjack": ("Blackjack-v1",), "cartpole": ("CartPole-v1",)}

GYM026 = Edition(
    name="gym026",
    number=2,
    title="OpenGym AI (gym 0.26 notebook)",
    api="gym026",
    registry=PROBLEMS,
    functions=tuple(
        ExpectedFunction(f.name, f.parameters, f.provided, _ENVS.get(f.name, f.env_ids))
        for f in CLASSIC_FUNCTIONS
    ),
    template=REPOSITORY / "submissions" / "templates" / "gym026.py",
    reference=REPOSITORY / "submissions" / "gym026_complete.py",
    default_config=BUNDLED_CONFIG,
    notebook_name="opengym.ipynb",
)
"""Graded like the first edition: the compatibility layer runs the 0.26 API and Blackjack-v1's rules."""
