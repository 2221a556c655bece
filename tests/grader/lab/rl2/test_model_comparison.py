"""model_comparison (2024) through the real sandbox: the honest file passes (slow: it trains 70 000 episodes),
and each mistaken or hostile one fails, named."""

from __future__ import annotations

from pathlib import Path

import pytest

from grader.lab.checks.base import Verdict
from grader.lab.games import FROZEN_LAKE_8X8
from grader.lab.rl2.checks.model_comparison import ModelComparisonCheck, ModelComparisonConfig

from .played_support import SAMPLES, settings, verdict_of

pytestmark = pytest.mark.slow  # through the sandbox

CHECK = ModelComparisonCheck()
BOUND = settings(
    ModelComparisonConfig, "model_comparison", (FROZEN_LAKE_8X8,), episodes=20, call_seconds=400.0
)
HONEST = (SAMPLES / "honest_v2024.py").read_text(encoding="utf-8")
HEAD = HONEST[: HONEST.index("def model_comparison(")]
PLAY = """
    env = gym.make("FrozenLake-v1", desc=None, map_name="8x8", is_slippery=True)
    nS, nA = env.observation_space.n, env.action_space.n
    V, _ = value_iteration(env.unwrapped.P, nS, nA)
    policy = policy_improvement(env.unwrapped.P, nS, nA, V)
"""


def _verdict(tmp_path: Path, body: str) -> Verdict:
    path = tmp_path / "policy_iteration.py"
    path.write_text(HEAD + "def model_comparison(episodes=1000):\n" + body, encoding="utf-8")
    return verdict_of(path, CHECK, BOUND)


def test_the_honest_2024_file_passes() -> None:
    verdict = verdict_of(SAMPLES / "honest_v2024.py", CHECK, BOUND)
    assert verdict.status == "passed", verdict.feedback


HOSTILE = {
    "returns_numbers_without_playing": (
        "    return 0.2, 0.8, 'value iteration wins'\n",
        "you played 0 episodes",
    ),
    "returns_no_statement": (
        PLAY
        + "    v = np.mean([run_simulation(env, policy) for _ in range(episodes)])\n"
        + "    return v, v, ''\n",
        "the statement is",
    ),
    "swaps_the_means": (
        PLAY.replace("nA)\n    policy", "nA)\n    zero = np.zeros(nS, dtype=int)\n    policy")
        + "    a = np.mean([run_simulation(env, zero) for _ in range(episodes)])\n"
        + "    b = np.mean([run_simulation(env, policy) for _ in range(episodes)])\n"
        + "    return b, a, 'swapped'\n",
        "as avg_Q_reward",
    ),
    "plays_a_poor_policy_as_value_iteration": (
        PLAY
        + "    zero = np.zeros(nS, dtype=int)\n"
        + "    a = np.mean([run_simulation(env, policy) for _ in range(episodes)])\n"
        + "    b = np.mean([run_simulation(env, zero) for _ in range(episodes)])\n"
        + "    return a, b, 'poor'\n",
        "never reach the goal",
    ),
}


@pytest.mark.parametrize("name", list(HOSTILE), ids=list(HOSTILE))
def test_each_mistaken_model_comparison_fails_and_is_named(tmp_path: Path, name: str) -> None:
    body, words = HOSTILE[name]
    verdict = _verdict(tmp_path, body)
    assert verdict.status == "failed", verdict.feedback
    assert words in verdict.feedback, verdict.feedback
