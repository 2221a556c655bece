"""frozen_lake (second lab) through the real sandbox: the honest files pass under their reading of the time
limit, a wrong solver is counted in its own problem, and each hostile or mistaken frozen_lake fails named."""

from __future__ import annotations

import math
import textwrap
from pathlib import Path

import pytest

from grader.lab.checks.base import Verdict
from grader.lab.games import FROZEN_LAKE_GAMES
from grader.lab.rl2.checks.frozen_lake import FrozenLakeCheck, FrozenLakeConfig, bernstein_half_width

from .played_support import SAMPLES, settings, verdict_of

pytestmark = pytest.mark.slow  # each test grades both lakes through the sandbox (5-15 s)

BOUND = settings(FrozenLakeConfig, "frozen_lake", FROZEN_LAKE_GAMES, episodes=20, call_seconds=60.0)
SIX = FrozenLakeCheck("frozen_lake", "six")
HONEST = (SAMPLES / "policy_function_iteration.py").read_text(encoding="utf-8")


def _verdict(tmp_path: Path, source: str, check: FrozenLakeCheck = SIX) -> Verdict:
    path = tmp_path / "policy_function_iteration.py"
    path.write_text(source, encoding="utf-8")
    return verdict_of(path, check, BOUND)


def _with(frozen_lake: str) -> str:
    """The honest 2026 file with its frozen_lake replaced."""
    head = HONEST[: HONEST.index("def frozen_lake(")]
    return head + textwrap.dedent(frozen_lake)


def test_bernstein_bound_is_the_stated_inequality() -> None:
    log_term = math.log(2 / 1e-6)
    assert bernstein_half_width(0.25, 100, 1e-6) == pytest.approx(
        math.sqrt(2 * 0.25 * log_term / 100) + log_term / 300
    )


@pytest.mark.parametrize(
    ("name", "check", "reading"),
    [
        ("honest_v2018.py", FrozenLakeCheck("frozenlake", "five"), "to the end, past the time limit"),
        ("honest_v2019.py", FrozenLakeCheck("frozen_lake", "five"), "to the end, past the time limit"),
        ("honest_v2023.py", FrozenLakeCheck("frozen_lake", "five"), "past the time limit"),
        ("honest_v2024.py", SIX, "up to the time limit"),
        ("policy_function_iteration.py", SIX, "up to the time limit"),
    ],
    ids=["v2018", "v2019", "v2023", "v2024", "v2026"],
)
def test_the_honest_file_of_every_edition_passes(name: str, check: FrozenLakeCheck, reading: str) -> None:
    """Classic `gym.make(id).env` and 2023's loop on `terminated` alone count episodes past the time limit."""
    verdict = verdict_of(SAMPLES / name, check, BOUND)
    assert verdict.status == "passed", verdict.feedback
    assert "exact reading" in verdict.feedback
    assert reading in verdict.feedback, verdict.feedback


def test_a_wrong_value_iteration_counts_in_its_own_problem_only() -> None:
    """First outcome only: a worse vi_policy on the slippery lakes, but the student's own solvers' answer."""
    verdict = verdict_of(SAMPLES / "mistakes" / "value_iteration_first_outcome.py", SIX, BOUND)
    assert verdict.status == "passed", verdict.feedback
    assert "own-solver reading" in verdict.feedback


HOSTILE = {
    "hard_codes_the_4x4_answers": (
        """
        def frozen_lake(basic_case=True, M=1000, render=False):
            V = np.array([0.82352941, 0.82352941, 0.82352941, 0.82352941, 0.82352941, 0, 0.52941176, 0,
                          0.82352941, 0.82352941, 0.76470588, 0, 0, 0.88235294, 0.94117647, 0])
            policy = np.array([0, 3, 3, 3, 0, 0, 0, 0, 3, 1, 0, 0, 0, 2, 1, 0])
            return V, policy, 0.74, V, policy, 0.74
        """,
        "you played 0 episodes",
    ),
    "returns_the_sum_not_the_mean": (
        """
        def frozen_lake(basic_case=True, M=1000, render=False):
            env = gym.make("FrozenLake-v1", map_name="4x4" if basic_case else "8x8", is_slippery=True)
            nS, nA = env.observation_space.n, env.action_space.n
            V, _ = value_iteration(env.unwrapped.P, nS, nA)
            policy = policy_improvement(env.unwrapped.P, nS, nA, V)
            pi_V, pi_policy, _ = policy_iteration(env.unwrapped.P, nS, nA)
            vi_sum = sum(run_simulation(env, policy) for _ in range(M))
            pi_sum = sum(run_simulation(env, pi_policy) for _ in range(M))
            return V, policy, vi_sum, pi_V, pi_policy, pi_sum
        """,
        "as the vi mean reward",
    ),
    "plays_the_deterministic_lake": (
        """
        def frozen_lake(basic_case=True, M=1000, render=False):
            env = gym.make("FrozenLake-v1", map_name="4x4" if basic_case else "8x8", is_slippery=False)
            nS, nA = env.observation_space.n, env.action_space.n
            V, _ = value_iteration(env.unwrapped.P, nS, nA)
            policy = policy_improvement(env.unwrapped.P, nS, nA, V)
            pi_V, pi_policy, _ = policy_iteration(env.unwrapped.P, nS, nA)
            vi = np.mean([run_simulation(env, policy) for _ in range(M)])
            pi = np.mean([run_simulation(env, pi_policy) for _ in range(M)])
            return V, policy, vi, pi_V, pi_policy, pi
        """,
        "is_slippery=False",
    ),
    "returns_another_policy_than_it_played": (
        """
        def frozen_lake(basic_case=True, M=1000, render=False):
            env = gym.make("FrozenLake-v1", map_name="4x4" if basic_case else "8x8", is_slippery=True)
            nS, nA = env.observation_space.n, env.action_space.n
            V, _ = value_iteration(env.unwrapped.P, nS, nA)
            policy = policy_improvement(env.unwrapped.P, nS, nA, V)
            pi_V, pi_policy, _ = policy_iteration(env.unwrapped.P, nS, nA)
            vi = np.mean([run_simulation(env, np.zeros(nS, dtype=int)) for _ in range(M)])
            pi = np.mean([run_simulation(env, pi_policy) for _ in range(M)])
            return V, policy, vi, pi_V, pi_policy, pi
        """,
        "but the policy you returned has",
    ),
    "returns_a_poor_policy_of_its_own": (
        """
        def frozen_lake(basic_case=True, M=1000, render=False):
            env = gym.make("FrozenLake-v1", map_name="4x4" if basic_case else "8x8", is_slippery=True)
            nS, nA = env.observation_space.n, env.action_space.n
            V, _ = value_iteration(env.unwrapped.P, nS, nA)
            policy = np.full(nS, 1)
            pi_V, pi_policy, _ = policy_iteration(env.unwrapped.P, nS, nA)
            vi = np.mean([run_simulation(env, policy) for _ in range(M)])
            pi = np.mean([run_simulation(env, pi_policy) for _ in range(M)])
            return V, policy, vi, pi_V, pi_policy, pi
        """,
        "vi_policy is not optimal",
    ),
    "leaves_the_policy_past_the_time_limit": (
        """
        def _play(env, policy):
            state, info = env.reset()
            total, k, terminated = 0.0, 0, False
            while not terminated:
                action = (int(policy[state]) + 1) % 4 if k == 100 else int(policy[state])
                state, reward, terminated, truncated, info = env.step(action)
                total, k = total + reward, k + 1
            return total


        def frozen_lake(basic_case=True, M=1000, render=False):
            env = gym.make("FrozenLake-v1", map_name="4x4" if basic_case else "8x8", is_slippery=True).env
            nS, nA = env.observation_space.n, env.action_space.n
            V, _ = value_iteration(env.unwrapped.P, nS, nA)
            policy = policy_improvement(env.unwrapped.P, nS, nA, V)
            pi_V, pi_policy, _ = policy_iteration(env.unwrapped.P, nS, nA)
            vi = np.mean([_play(env, policy) for _ in range(M)])
            pi = np.mean([_play(env, pi_policy) for _ in range(M)])
            return V, policy, vi, pi_V, pi_policy, pi
        """,
        "(past gym.make's time limit)",
    ),
    "returns_five_results_in_a_six_result_edition": (
        """
        def frozen_lake(basic_case=True, M=1000, render=False):
            return None, None, None, None, None
        """,
        "expected 6 results",
    ),
}


@pytest.mark.parametrize("name", list(HOSTILE), ids=list(HOSTILE))
def test_each_hostile_or_mistaken_frozen_lake_fails_and_is_named(tmp_path: Path, name: str) -> None:
    body, words = HOSTILE[name]
    verdict = _verdict(tmp_path, _with(body))
    assert verdict.status == "failed", verdict.feedback
    assert words in verdict.feedback, verdict.feedback


PEEKING = """
import copy


def _wins(lake, policy):
    state, done, reward = lake.s, False, 0.0
    while not done:
        state, reward, terminated, truncated, _ = lake.step(int(policy[state]))
        done = terminated or truncated
    return reward > 0


def _peeking_mean(env, policy, M):
    total = 0.0
    for _ in range(M):
        env.reset()
        if not _wins(copy.deepcopy(env.unwrapped), policy):  # a lost game ahead: deal another
            env.reset()
        state, done = env.unwrapped.s, False
        while not done:
            state, reward, terminated, truncated, _ = env.step(int(policy[state]))
            total += reward
            done = terminated or truncated
    return total / M


def frozen_lake(basic_case=True, M=1000, render=False):
    env = gym.make("FrozenLake-v1", map_name="4x4" if basic_case else "8x8", is_slippery=True)
    nS, nA = env.observation_space.n, env.action_space.n
    V, _ = value_iteration(env.unwrapped.P, nS, nA)
    policy = policy_improvement(env.unwrapped.P, nS, nA, V)
    pi_V, pi_policy, _ = policy_iteration(env.unwrapped.P, nS, nA)
    return V, policy, _peeking_mean(env, policy, M), pi_V, pi_policy, _peeking_mean(env, pi_policy, M)
"""


def test_episodes_chosen_by_peeking_at_the_generator_fail_the_mean_test(tmp_path: Path) -> None:
    """Every reset's start is state 0, so no start can be chosen; this file copies the env (its generator
    included) to see whether the game dealt will be won, and deals another when it will not. Every action
    is the policy's, every mean the replay's: only the mean test can tell, and at the lab's M = 1 000 it does
    (the 4x4 mean under the 100-step limit, exactly 0.740, raised to about 0.86; Bernstein's half-width
    0.082 at alpha 1e-6; at M = 400 the half-width, 0.130, is too wide)."""
    path = tmp_path / "policy_function_iteration.py"
    path.write_text(_with(PEEKING), encoding="utf-8")
    wide = settings(FrozenLakeConfig, "frozen_lake", FROZEN_LAKE_GAMES, episodes=1000, call_seconds=60.0)
    verdict = verdict_of(path, SIX, wide)
    assert verdict.status == "failed", verdict.feedback
    assert "not a fair sample" in verdict.feedback, verdict.feedback
