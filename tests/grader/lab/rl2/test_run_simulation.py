"""run_simulation (second lab) through the real sandbox: honest files of every edition pass, each mistake
and each hostile sample fails (every verdict branch has one), and the samples get their pinned verdicts."""

from __future__ import annotations

import textwrap
import tomllib
from pathlib import Path

import numpy as np
import pytest

from grader.lab.checks.base import Verdict
from grader.lab.games import RUN_SIMULATION_GAMES
from grader.lab.rl2.checks.run_simulation import (
    CASES,
    MISTAKES,
    RunSimulationCheck,
    RunSimulationConfig,
    discounted_return,
    planned_cases,
)

from .played_support import SAMPLES, settings, verdict_of

pytestmark = pytest.mark.slow  # every test grades through the sandbox (about a second each)

CHECK = RunSimulationCheck()
BOUND = settings(
    RunSimulationConfig, "run_simulation", RUN_SIMULATION_GAMES, slippery_calls=4, call_seconds=5.0
)
VERDICTS = tomllib.loads((SAMPLES / "verdicts.toml").read_text(encoding="utf-8"))["sample"]
PINNED = [sample for sample in VERDICTS if "run_simulation" in sample["status"]]

HEADER = "import numpy as np\nimport gymnasium as gym\n\n"
HONEST_BODY = """\
observation, info = env.reset()
total, k, done = 0.0, 0, False
while not done:
    observation, reward, terminated, truncated, info = env.step(int(policy[observation]))
    total += beta**k * reward
    k += 1
    done = terminated or truncated
"""


def _source(body: str, extra: str = "") -> str:
    code = textwrap.dedent(body).lstrip("\n")
    return HEADER + extra + "def run_simulation(env, policy, beta=1.0):\n" + textwrap.indent(code, "    ")


def _verdict(tmp_path: Path, source: str) -> Verdict:
    path = tmp_path / "policy_function_iteration.py"
    path.write_text(source, encoding="utf-8")
    return verdict_of(path, CHECK, BOUND)


def test_the_discounted_return_counts_from_step_zero() -> None:
    assert discounted_return([0.0, 0.0, 1.0], 0.5) == 0.25
    assert discounted_return([-1.0, -1.0, 20.0], 0.9) == pytest.approx(-1 - 0.9 + 20 * 0.81)


def test_every_grader_case_plays_its_own_policy_and_the_mistakes_differ_on_some_case() -> None:
    """Each typical mistake's return differs from the honest one on a deterministic episode of the plan."""
    assert len(planned_cases(BOUND)) == 4 + 3 * 4
    rewards = {"lake": [0.0] * 5 + [1.0], "taxi": [-1.0] * 9 + [20.0]}
    for cause, mistaken in MISTAKES:
        assert any(
            abs(mistaken(steps, beta) - discounted_return(steps, beta)) > 1e-6
            for steps in rewards.values()
            for beta in {case.beta for case in CASES}
        ), cause


@pytest.mark.parametrize(
    "name",
    [
        "honest_v2018.py",
        "honest_v2019.py",
        "honest_v2023.py",
        "honest_v2024.py",
        "policy_function_iteration.py",
    ],
)
def test_the_honest_file_of_every_edition_passes(name: str) -> None:
    verdict = verdict_of(SAMPLES / name, CHECK, BOUND)
    assert verdict.status == "passed", verdict.feedback
    assert verdict.measurements["calls_with_the_replayed_return"] == len(planned_cases(BOUND))


@pytest.mark.parametrize("sample", PINNED, ids=[sample["file"] for sample in PINNED])
def test_each_sample_gets_its_pinned_verdict(sample: dict) -> None:  # type: ignore[type-arg]
    verdict = verdict_of(SAMPLES.parent / sample["file"], CHECK, BOUND)
    assert verdict.status == sample["status"]["run_simulation"], verdict.feedback
    words = sample.get("feedback", {}).get("run_simulation")
    if words:
        assert words in verdict.feedback, verdict.feedback


HOSTILE = {
    "returns_without_playing": (
        "return 0.59\n",
        "",
        "failed",
        "without playing an episode",
    ),
    "plays_its_own_env_with_its_own_seed": (
        """
        spec = env.unwrapped.spec  # the same game as the env passed, made anew
        own = gym.make(spec.id, **spec.kwargs)
        observation, info = own.reset(seed=3)
        total, k, done = 0.0, 0, False
        while not done:
            observation, reward, terminated, truncated, info = own.step(int(policy[observation]))
            total += beta**k * reward
            k += 1
            done = terminated or truncated
        return total
        """,
        "",
        "failed",
        "made itself",
    ),
    "returns_a_float_subclass": (
        HONEST_BODY + "return Rigged(total)\n",
        "class Rigged(float):\n    def __eq__(self, other):\n        return True\n\n\n",
        "error",
        "subclass",
    ),
    "plays_forever": (
        """
        observation, info = env.reset()
        while True:
            env.step(int(policy[observation]))
        """,
        "",
        "timeout",
        "did not return within 5 seconds",
    ),
    "plays_many_episodes": (
        HONEST_BODY + "for _ in range(30):\n    env.reset()\nreturn total\n",
        "",
        "failed",
        "the grader records at most 10 resets",
    ),
    "returns_the_last_reward_only": (
        """
        observation, info = env.reset()
        done = False
        while not done:
            observation, reward, terminated, truncated, info = env.step(int(policy[observation]))
            done = terminated or truncated
        return reward
        """,
        "",
        "failed",
        "the last reward only",
    ),
    "does_not_reset": (
        """
        observation, total, k, done = 0, 0.0, 0, False
        while not done:
            observation, reward, terminated, truncated, info = env.step(int(policy[observation]))
            total += beta**k * reward
            k += 1
            done = terminated or truncated
        return total
        """,
        "",
        "failed",
        "before resetting it",
    ),
    "closes_the_env": (HONEST_BODY + "env.close()\nreturn total\n", "", "failed", "closed the env"),
    "ignores_the_policy": (
        HONEST_BODY.replace("int(policy[observation])", "2") + "return total\n",
        "",
        "failed",
        "the policy passed has",
    ),
    "returns_a_list": (HONEST_BODY + "return [total]\n", "", "failed", "expected one number"),
    "plays_two_episodes": (
        HONEST_BODY + "env.reset()\nenv.step(0)\nreturn total\n",
        "",
        "failed",
        "abandoned",
    ),
    "plays_two_whole_episodes": (
        HONEST_BODY + "first = total\n" + HONEST_BODY + "return first\n",
        "",
        "failed",
        "run_simulation plays ONE episode",
    ),
    "adds_a_constant": (HONEST_BODY + "return total + 0.5\n", "", "failed", "k counted from 0"),
    "discount_applied_to_the_policy_not_the_reward": (
        HONEST_BODY.replace("beta**k * reward", "reward * beta**(k + 1) / beta**0") + "return total\n",
        "",
        "failed",
        "discount from k = 1",
    ),
}


@pytest.mark.parametrize("name", list(HOSTILE), ids=list(HOSTILE))
def test_each_hostile_or_mistaken_function_fails_and_is_named(tmp_path: Path, name: str) -> None:
    body, extra, status, words = HOSTILE[name]
    verdict = _verdict(tmp_path, _source(body, extra))
    assert verdict.status == status, verdict.feedback
    assert words in verdict.feedback, verdict.feedback
    if name == "closes_the_env":
        assert verdict.fraction == BOUND.closing_fraction


def test_the_honest_body_passes_when_written_here(tmp_path: Path) -> None:
    verdict = _verdict(tmp_path, _source(HONEST_BODY + "return total\n"))
    assert verdict.status == "passed", verdict.feedback


def test_render_is_passed_false_in_third_place(tmp_path: Path) -> None:
    """2019-2022: run_simulation(env, policy, render=True, beta=1.0); a render=True would draw (and fail)."""
    source = HEADER + textwrap.dedent(
        """
        def run_simulation(env, policy, render=True, beta=1.0):
            if render:
                raise RuntimeError("the grader must pass render=False")
            obs = env.reset()
            total, k, done = 0.0, 0, False
            while not done:
                obs, reward, done, _ = env.step(int(policy[obs]))
                total += beta**k * reward
                k += 1
            return total
        """
    )
    verdict = _verdict(tmp_path, source)
    assert verdict.status == "passed", verdict.feedback


def test_a_stub_is_missing(tmp_path: Path) -> None:
    verdict = _verdict(tmp_path, _source('raise NotImplementedError("Problem 5 incomplete")\n'))
    assert verdict.status == "missing"
    assert np.isfinite(len(verdict.feedback))
