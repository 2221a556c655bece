"""The second lab's editions as packs: every fact about them declared once, here.

Each edition is an `Edition` (`lab="rl2"`) with its registry of problems (ids are the edition's function
names), every function its template defines, its template, reference, default configuration
(`grader/lab/rl2/<edition>.toml`) and file name. The pure problems are shared declarations (the two
readings of value iteration's n, the two namings of the improvement and evaluation steps, the two
`policy_iteration`s bound to their edition's step names); an edition's registry is built from a tuple of them
(`PURE_2018`, `PURE_2023`, `PURE_2024`) and the played problems (`run_simulation`, `frozen_lake`/`frozenlake`,
`model_comparison`).
"""

from __future__ import annotations

from dataclasses import replace

from grader.lab.editions.pack import REPOSITORY, Edition, ExpectedFunction
from grader.lab.games import FROZEN_LAKE_GAMES, RUN_SIMULATION_GAMES
from grader.lab.registry import Problem, Registry
from grader.lab.rl2.checks.evaluation import EvaluationCheck, EvaluationConfig
from grader.lab.rl2.checks.frozen_lake import FrozenLakeCheck, FrozenLakeConfig
from grader.lab.rl2.checks.improvement import ImprovementCheck, ImprovementConfig
from grader.lab.rl2.checks.model_comparison import ModelComparisonCheck, ModelComparisonConfig
from grader.lab.rl2.checks.policy_iteration import PolicyIterationCheck, PolicyIterationConfig
from grader.lab.rl2.checks.run_simulation import RunSimulationCheck, RunSimulationConfig
from grader.lab.rl2.checks.value_iteration import ValueIterationCheck, ValueIterationConfig

LAB = "rl2"
"""The lab's name (`Edition.lab`)."""
PACKAGE = REPOSITORY / "grader" / "lab" / "rl2"
SUBMISSIONS = REPOSITORY / "submissions" / "rl2"

VALUE_ITERATION_2018 = Problem(
    id="value_iteration",
    title="Problem 1: value_iteration",
    points=1.0,
    config=ValueIterationConfig,
    check=ValueIterationCheck(changes_counted=True),
)
"""The 2018 to mid-2022 texts: their example stops at "V2 = [1, 1, 1, 0], which is the solution", so n may
count the sweeps that changed V (2 there) as well as the sweeps made (3)."""
VALUE_ITERATION = Problem(
    id="value_iteration",
    title="Problem 1: value_iteration",
    points=1.0,
    config=ValueIterationConfig,
    check=ValueIterationCheck(),
)
"""The texts since mid-2022: "Repeating a third time gives V3 = [1, 1, 1, 0], which is the same as V2, so the
process has converged": n = 3 on the example."""
EXTRACT_POLICY = Problem(
    id="extract_policy",
    title="Problem 2: extract_policy",
    points=1.0,
    config=ImprovementConfig,
    check=ImprovementCheck("extract_policy"),
)
POLICY_IMPROVEMENT = Problem(
    id="policy_improvement",
    title="Problem 2: policy_improvement",
    points=1.0,
    config=ImprovementConfig,
    check=ImprovementCheck("policy_improvement"),
)
COMPUTE_POLICY_V = Problem(
    id="compute_policy_v",
    title="Problem 3: compute_policy_v",
    points=1.0,
    config=EvaluationConfig,
    check=EvaluationCheck("compute_policy_v"),
)
ITER_POLICY_EVAL = Problem(
    id="iter_policy_eval",
    title="Problem 3: iter_policy_eval",
    points=1.0,
    config=EvaluationConfig,
    check=EvaluationCheck("iter_policy_eval"),
)
POLICY_ITERATION_2018 = Problem(
    id="policy_iteration",
    title="Problem 4: policy_iteration",
    points=1.0,
    config=PolicyIterationConfig,
    check=PolicyIterationCheck(evaluation="compute_policy_v", improvement="extract_policy"),
)
POLICY_ITERATION_2024 = Problem(
    id="policy_iteration",
    title="Problem 4: policy_iteration",
    points=1.0,
    config=PolicyIterationConfig,
    check=PolicyIterationCheck(evaluation="iter_policy_eval", improvement="policy_improvement"),
)

RUN_SIMULATION = Problem(
    id="run_simulation",
    title="Problem 6: run_simulation",
    points=1.0,
    config=RunSimulationConfig,
    check=RunSimulationCheck(),
    games=RUN_SIMULATION_GAMES,
)
RUN_SIMULATION_2026 = replace(RUN_SIMULATION, title="Problem 5: run_simulation")
"""The 2026 template swaps the numbers of run_simulation and frozen_lake; nothing else differs."""

FROZENLAKE_2018 = Problem(
    id="frozenlake",
    title="Problem 5: frozenlake",
    points=1.0,
    config=FrozenLakeConfig,
    check=FrozenLakeCheck("frozenlake", "five"),
    games=FROZEN_LAKE_GAMES,
)
FROZEN_LAKE_2019 = Problem(
    id="frozen_lake",
    title="Problem 5: frozen_lake",
    points=1.0,
    config=FrozenLakeConfig,
    check=FrozenLakeCheck("frozen_lake", "five"),
    games=FROZEN_LAKE_GAMES,
)
FROZEN_LAKE_2024 = Problem(
    id="frozen_lake",
    title="Problem 5: frozen_lake",
    points=1.0,
    config=FrozenLakeConfig,
    check=FrozenLakeCheck("frozen_lake", "six"),
    games=FROZEN_LAKE_GAMES,
)
FROZEN_LAKE_2026 = replace(FROZEN_LAKE_2024, title="Problem 6: frozen_lake")

MODEL_COMPARISON = Problem(
    id="model_comparison",
    title="Problem 7: model_comparison",
    points=1.0,
    config=ModelComparisonConfig,
    check=ModelComparisonCheck(),
    games=(FROZEN_LAKE_GAMES[1],),
)

PURE_2018 = (VALUE_ITERATION_2018, EXTRACT_POLICY, COMPUTE_POLICY_V, POLICY_ITERATION_2018)
"""The pure problems of the 2018-2022 editions (v2018, v2019), in lab order."""
PURE_2023 = (VALUE_ITERATION, EXTRACT_POLICY, COMPUTE_POLICY_V, POLICY_ITERATION_2018)
"""The pure problems of the 2023 edition: the 2018 names, the example counted to n = 3."""
PURE_2024 = (VALUE_ITERATION, POLICY_IMPROVEMENT, ITER_POLICY_EVAL, POLICY_ITERATION_2024)
"""The pure problems of the 2024 and 2026 editions, in lab order."""


def _solvers(beta: str, improvement: str, values: str, evaluation: str) -> tuple[ExpectedFunction, ...]:
    return (
        ExpectedFunction("value_iteration", ("P", "nS", "nA", f"beta={beta}", "tol=1e-8", "maxiter=3000")),
        ExpectedFunction(improvement, ("P", "nS", "nA", values, "beta=1.0")),
        ExpectedFunction(evaluation, ("P", "nS", "nA", "policy", "beta=1.0", "tol=1e-8")),
        ExpectedFunction("policy_iteration", ("P", "nS", "nA", f"beta={beta}", "tol=1e-8", "maxiter=200")),
    )


_CLASSIC_LAKES = ("FrozenLake-v0", "FrozenLake8x8-v0")
_LAKES = ("FrozenLake-v1",)

V2018 = Edition(
    name="v2018",
    number=1,
    title="Policy Function Iteration (2018, gym 0.10)",
    api="classic",
    lab=LAB,
    registry=Registry((*PURE_2018, FROZENLAKE_2018, RUN_SIMULATION)),
    functions=(
        *_solvers("1", "extract_policy", "v", "compute_policy_v"),
        ExpectedFunction("frozenlake", ("basic_case=True", "M=1000"), env_ids=_CLASSIC_LAKES),
        ExpectedFunction("run_simulation", ("env", "policy", "beta=1.0"), env_ids=_CLASSIC_LAKES),
    ),
    template=SUBMISSIONS / "templates" / "v2018.py",
    reference=SUBMISSIONS / "honest_v2018.py",
    default_config=PACKAGE / "v2018.toml",
    notebook_name="policy_iteration.py",
)

V2019 = Edition(
    name="v2019",
    number=2,
    title="Policy Function Iteration (2019-2022, gym)",
    api="classic",
    lab=LAB,
    registry=Registry((*PURE_2018, FROZEN_LAKE_2019, RUN_SIMULATION)),
    functions=(
        *_solvers("1", "extract_policy", "v", "compute_policy_v"),
        ExpectedFunction("frozen_lake", ("basic_case=True", "M=1000", "render=False"), env_ids=_LAKES),
        ExpectedFunction("run_simulation", ("env", "policy", "render=True", "beta=1.0"), env_ids=_LAKES),
    ),
    template=SUBMISSIONS / "templates" / "v2019.py",
    reference=SUBMISSIONS / "honest_v2019.py",
    default_config=PACKAGE / "v2019.toml",
    notebook_name="policy_iteration.py",
)

V2023 = Edition(
    name="v2023",
    number=3,
    title="Policy Function Iteration (2023, gymnasium)",
    api="gymnasium",
    lab=LAB,
    registry=Registry((*PURE_2023, FROZEN_LAKE_2019, RUN_SIMULATION)),
    functions=(
        *_solvers("1.0", "extract_policy", "v", "compute_policy_v"),
        ExpectedFunction("frozen_lake", ("basic_case=True", "M=1000", "render=False"), env_ids=_LAKES),
        ExpectedFunction("run_simulation", ("env", "policy", "beta=1.0"), env_ids=_LAKES),
    ),
    template=SUBMISSIONS / "templates" / "v2023.py",
    reference=SUBMISSIONS / "honest_v2023.py",
    default_config=PACKAGE / "v2023.toml",
    notebook_name="policy_iteration.py",
)

V2024 = Edition(
    name="v2024",
    number=4,
    title="Reinforcement Learning 2: Markov Decision Process (2024)",
    api="gymnasium",
    lab=LAB,
    registry=Registry((*PURE_2024, FROZEN_LAKE_2024, RUN_SIMULATION, MODEL_COMPARISON)),
    functions=(
        *_solvers("1.0", "policy_improvement", "V", "iter_policy_eval"),
        ExpectedFunction("frozen_lake", ("basic_case=True", "M=1000", "render=False"), env_ids=_LAKES),
        ExpectedFunction("run_simulation", ("env", "policy", "beta=1.0"), env_ids=_LAKES),
        ExpectedFunction("model_comparison", ("episodes=1000",), env_ids=_LAKES),
    ),
    template=SUBMISSIONS / "templates" / "v2024.py",
    reference=SUBMISSIONS / "honest_v2024.py",
    default_config=PACKAGE / "v2024.toml",
    notebook_name="policy_iteration.py",
)

V2026 = Edition(
    name="v2026",
    number=5,
    title="Reinforcement Learning 2: Markov Decision Process (2026 template)",
    api="gymnasium",
    lab=LAB,
    registry=Registry((*PURE_2024, RUN_SIMULATION_2026, FROZEN_LAKE_2026)),
    functions=(
        *_solvers("1.0", "policy_improvement", "V", "iter_policy_eval"),
        ExpectedFunction("run_simulation", ("env", "policy", "beta=1.0"), env_ids=_LAKES),
        ExpectedFunction("frozen_lake", ("basic_case=True", "M=1000", "render=False"), env_ids=_LAKES),
    ),
    template=SUBMISSIONS / "templates" / "v2026.py",
    reference=SUBMISSIONS / "policy_function_iteration.py",
    default_config=PACKAGE / "v2026.toml",
    notebook_name="policy_function_iteration.py",
)

EDITIONS = (V2018, V2019, V2023, V2024, V2026)
"""The second lab's editions, oldest first."""
