"""Edition 4, "Reinforcement Learning 1: Gymnasium" (2024 onwards), the one taught today.

Problems 1-4 are the shared declarations of `grader.lab.problems`; `epsilon_decay` and the two-table
`taxi(q_table, q_table_decay)` are this edition's own, and `sarsa0` (given the environment's name, as the
course's template has it), verified by replaying its updates (`grader.lab.checks.sarsa`). `compare()` is
graded on the grader's tables bound to the globals it reads (`bind_tables`; the notebook's cells run in the
sandbox where that cannot serve; `run_cells = false`: skipped, worth 0: `grader.lab.checks.compare`).
"""

from grader.lab.checks.compare import CompareCheck, CompareConfig
from grader.lab.checks.epsilon_decay import EpsilonDecayCheck, EpsilonDecayConfig
from grader.lab.checks.sarsa import SarsaCheck, SarsaConfig
from grader.lab.checks.taxi_tables import TaxiTablesCheck, TaxiTablesConfig
from grader.lab.editions.pack import PACKAGE, REPOSITORY, Edition, ExpectedFunction
from grader.lab.games import TAXI_GAMES
from grader.lab.problems import PROBLEMS
from grader.lab.registry import Problem, Registry
from grader.lab.showcase import LAST_TAXI_OF_FIRST_CALL

_LEARNER = ("env", "alpha=0.1", "gamma=0.6", "epsilon=0.1", "N=70_000", "decay=False")

FUNCTIONS = (
    ExpectedFunction("random_blackjack", ("n",), env_ids=("Blackjack-v1",)),
    ExpectedFunction("blackjack", ("n=11",), env_ids=("Blackjack-v1",)),
    ExpectedFunction("cartpole", ("render=False",), env_ids=("CartPole-v1",)),
    ExpectedFunction("car", ("render=False",), env_ids=("MountainCar-v0",)),
    ExpectedFunction("epsilon_decay", ("episode", "N", "epsilon_start=1.0", "epsilon_end=1e-6")),
    ExpectedFunction("qlearn", _LEARNER, provided=True, env_ids=("Taxi-v3",)),
    ExpectedFunction("taxi", ("q_table", "q_table_decay"), env_ids=("Taxi-v3",)),
    ExpectedFunction("sarsa0", _LEARNER, env_ids=("Taxi-v3",)),
    ExpectedFunction("compare", (), env_ids=("Taxi-v3",)),
)

RL1 = Edition(
    name="rl1",
    number=4,
    title="Reinforcement Learning 1: Gymnasium",
    api="gymnasium",
    registry=Registry(
        (
            PROBLEMS.problem("random_blackjack"),
            PROBLEMS.problem("blackjack"),
            PROBLEMS.problem("cartpole"),
            PROBLEMS.problem("car"),
            Problem(
                id="epsilon_decay",
                title="Problem 5: epsilon_decay",
                points=1.0,
                config=EpsilonDecayConfig,
                check=EpsilonDecayCheck(),
            ),
            Problem(
                id="taxi",
                title="Problem 6: Taxi with two tables",
                points=1.0,
                config=TaxiTablesConfig,
                check=TaxiTablesCheck(),
                games=TAXI_GAMES,
                showcase=LAST_TAXI_OF_FIRST_CALL,
            ),
            Problem(
                id="sarsa0",
                title="Problem 7: SARSA(0)",
                points=1.0,
                config=SarsaConfig,
                check=SarsaCheck(),
            ),
            Problem(
                id="compare",
                title="Problem 7: compare()",
                points=1.0,
                config=CompareConfig,
                check=CompareCheck(),
                games=TAXI_GAMES,
            ),
        )
    ),
    functions=FUNCTIONS,
    template=REPOSITORY / "submissions" / "templates" / "rl1.py",
    reference=REPOSITORY / "submissions" / "editions" / "rl1_complete.py",
    default_config=PACKAGE / "rl1.toml",
    notebook_name="gymnasium.ipynb",
    not_graded=(
        (
            "qlearn",
            "provided by the template; taxi gets the grader's own tables, so no verdict needs it; "
            "it runs only where the notebook's cells run before compare() (binding cannot serve)",
        ),
    ),
)
"""The current edition: problems 1-7 graded (compare() on bound tables); qlearn not graded."""
