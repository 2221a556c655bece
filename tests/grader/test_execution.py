"""Tests of grader/execution.py that need no sandbox: per-problem seeds and trusted replays."""

from __future__ import annotations

import warnings

import gymnasium
import pytest

from grader.execution import problem_seed, trusted_replays
from grader.problems import PROBLEM_IDS
from grader.sandbox import Call, CallOutcome, EpisodeLog, OutcomeStatus
from grader.sandbox.child.seeding import reset_seeds


@pytest.mark.parametrize(
    ("grading_seed", "problem", "expected"),
    [
        (0, "cartpole", 2777628367144785276),
        (1, "cartpole", 485058722580370561),
        (0, "taxi", 6027082271082110006),
    ],
    ids=["seed-0-cartpole", "seed-1-cartpole", "seed-0-taxi"],
)
def test_problem_seeds_never_change(grading_seed: int, problem: str, expected: int) -> None:
    """Pinned: changing the derivation would silently change every past grade's episodes."""
    assert problem_seed(grading_seed, problem) == expected


def test_problem_seeds_are_distinct_63_bit_numbers() -> None:
    seeds = {problem_seed(grading_seed, problem) for grading_seed in range(50) for problem in PROBLEM_IDS}
    assert len(seeds) == 50 * len(PROBLEM_IDS)
    assert all(0 <= seed < 2**63 for seed in seeds)


def _cartpole_outcome(call_seed: int, reset_seed: int) -> CallOutcome:
    """A call that played one CartPole-v0 episode, pushing right, reset with `reset_seed`."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", ".*CartPole-v0 is out of date", DeprecationWarning)
        env = gymnasium.make("CartPole-v0")
    env.reset(seed=reset_seed)
    rewards, terminated, truncated = [], [], []
    done = False
    while not done:
        _, reward, ended, cut, _ = env.step(1)
        rewards.append(float(reward))
        terminated.append(bool(ended))
        truncated.append(bool(cut))
        done = ended or cut
    log = EpisodeLog(
        env_index=0,
        requested_id="CartPole-v0",
        env_id="CartPole-v0",
        env_kwargs={},
        reset_seed=reset_seed,
        student_seed=None,
        actions=[1] * len(rewards),
        rewards=rewards,
        terminated=terminated,
        truncated=truncated,
    )
    return CallOutcome(
        call=Call("cartpole"),
        status=OutcomeStatus.OK,
        value=len(rewards),
        episodes=[log],
        compat_events=[],
        stdout="",
        stderr="",
        message="",
        wall_time=0.0,
        seed=call_seed,
    )


def test_episodes_reset_from_the_grader_stream_are_trusted() -> None:
    call_seed = 1234
    (replay,) = trusted_replays(_cartpole_outcome(call_seed, reset_seeds(call_seed, 1)[0]))

    assert replay.mismatch is None


def test_episodes_reset_with_seeds_of_their_own_choosing_do_not_replay() -> None:
    call_seed = 1234
    chosen = reset_seeds(call_seed, 1)[0] + 1
    (replay,) = trusted_replays(_cartpole_outcome(call_seed, chosen))

    assert replay.mismatch == (
        f"episode 1 was reset with seed {chosen}, but the grader's seed stream gives {chosen - 1}: "
        "the episode log was altered"
    )
