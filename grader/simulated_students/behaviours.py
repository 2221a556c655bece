"""Simulated students: the reference's policies and the typical mistakes, for calibration and tests.

Each behaviour maps function names to functions run by `grader.simulated_students.simulation` (first argument:
the simulated `Lab`). `BEHAVIOURS` names every behaviour with the problem it is about and the status the
checks must give it; `submissions/mistakes/` holds the same mistakes as real student files.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np

from grader.lab.checks.base import ProblemId, Status
from grader.simulated_students.simulation import Lab, LabEnv, StudentFunction

BLACKJACK_GAMES = 10_000
TAXI_EPISODES = 10_000

Policy = Callable[[Any], int]


def _play_blackjack(env: LabEnv, policy: Callable[[Any, int], int]) -> float:
    """Play one game; policy gets (observation, decision index). Returns the final reward."""
    observation, _ = env.reset()
    reward, done, step = 0.0, False, 0
    while not done:
        observation, reward, terminated, truncated, _ = env.step(policy(observation, step))
        done, step = terminated or truncated, step + 1
    return reward


def random_blackjack(lab: Lab, n: int, *, env_id: str = "Blackjack-v0") -> float:
    """Reference: n games with random actions; the fraction won."""
    env = lab.make(env_id)
    rewards = [
        _play_blackjack(env, lambda _observation, _step: int(env.action_space.sample())) for _ in range(n)
    ]
    return sum(reward > 0 for reward in rewards) / n


def blackjack(lab: Lab, n: int, games: int = BLACKJACK_GAMES, *, env_id: str = "Blackjack-v0") -> float:
    """Reference: draw while the sum is <= n over 10000 games; the fraction won."""
    env = lab.make(env_id)
    rewards = [
        _play_blackjack(env, lambda observation, _step: int(observation[0] <= n)) for _ in range(games)
    ]
    return sum(reward > 0 for reward in rewards) / games


def _episode_length(env: LabEnv, policy: Policy, seed: int | None = None) -> int:
    observation, _ = env.reset(seed=seed)
    steps, done = 0, False
    while not done:
        observation, _, terminated, truncated, _ = env.step(policy(observation))
        steps, done = steps + 1, terminated or truncated
    return steps


def velocity_policy(observation: Any) -> int:
    """The lab's CartPole policy: push the way the pole's tip moves."""
    return 1 if observation[3] > 0 else 0


def cartpole(lab: Lab, *, env_id: str = "CartPole-v0") -> int:
    """Reference: one CartPole-v0 episode with the velocity policy; its length."""
    return _episode_length(lab.make(env_id), velocity_policy)


def car_policy(observation: Any) -> int:
    """The reference MountainCar policy: push along the velocity."""
    return 2 if observation[1] >= 0 else 0


def car(lab: Lab) -> int:
    """Reference: one MountainCar-v0 episode pushing along the velocity; its length."""
    return _episode_length(lab.make("MountainCar-v0"), car_policy)


def _random_step_first(lab: Lab, env_id: str, policy: Policy, *, counted_from: int = 0) -> int:
    """The lab-era pattern: reset, one random step, then count the steps of the loop (from `counted_from`)."""
    env = lab.make(env_id)
    env.reset()
    observation, _, terminated, truncated, _ = env.step(int(env.action_space.sample()))
    steps, done = counted_from, terminated or truncated
    while not done:
        observation, _, terminated, truncated, _ = env.step(policy(observation))
        steps, done = steps + 1, terminated or truncated
    return steps


def _counted_from_one(lab: Lab) -> int:
    return cartpole(lab) + 1


def _taxi_ignoring_truncation(lab: Lab, q_table: np.ndarray, episodes: int = 10) -> list[float]:
    """gym 0.26 code that loops `while not terminated`: random episodes run until the passenger arrives.

    At most 10 episodes per scenario whatever `episodes` asks: the first ones show the pattern, and the
    lab's 10000 unlimited random episodes would take about 100 million steps.
    """
    episodes = min(episodes, 10)
    env = lab.make("Taxi-v3")
    greedy = np.argmax(q_table, axis=1)
    means = []
    policies: tuple[Policy, Policy] = (
        lambda _state: int(env.action_space.sample()),
        lambda state: int(greedy[state]),
    )
    for policy in policies:
        totals = []
        for _ in range(episodes):
            state, _ = env.reset()
            total, terminated = 0.0, False
            while not terminated:
                state, reward, terminated, _, _ = env.step(policy(state))
                total += float(reward)
            totals.append(total)
        means.append(sum(totals) / episodes)
    return means


def _taxi_return(env: LabEnv, policy: Policy, *, seed: int | None = None, final_only: bool = False) -> float:
    state, _ = env.reset(seed=seed)
    total, reward, done = 0.0, 0.0, False
    while not done:
        state, reward, terminated, truncated, _ = env.step(policy(state))
        total, done = total + reward, terminated or truncated
    return reward if final_only else total


def taxi(
    lab: Lab,
    q_table: np.ndarray,
    *,
    env_id: str = "Taxi-v3",
    final_only: bool = False,
    seed: int | None = None,
    episodes: int = TAXI_EPISODES,
) -> list[float]:
    """Reference: (mean total reward of random episodes, of greedy episodes on the given table)."""
    env = lab.make(env_id)
    greedy = np.argmax(q_table, axis=1)
    means = []
    for policy in (lambda _state: int(env.action_space.sample()), lambda state: int(greedy[state])):
        returns = [_taxi_return(env, policy, seed=seed, final_only=final_only) for _ in range(episodes)]
        means.append(sum(returns) / episodes)
    return means


def _less_than(lab: Lab, n: int, games: int = BLACKJACK_GAMES) -> float:
    env = lab.make("Blackjack-v0")
    rewards = [_play_blackjack(env, lambda observation, _step: int(observation[0] < n)) for _ in range(games)]
    return sum(reward > 0 for reward in rewards) / games


def _stale_hand(lab: Lab, n: int, games: int = BLACKJACK_GAMES) -> float:
    env = lab.make("Blackjack-v0")
    hand = 0
    wins = 0
    for _ in range(games):
        env.reset()
        done, reward = False, 0.0
        while not done:
            observation, reward, terminated, truncated, _ = env.step(int(hand <= n))
            hand, done = observation[0], terminated or truncated
        wins += reward > 0
    return wins / games


def _average_reward(lab: Lab, n: int) -> float:
    env = lab.make("Blackjack-v0")
    rewards = [
        _play_blackjack(env, lambda _observation, _step: int(env.action_space.sample())) for _ in range(n)
    ]
    return sum(rewards) / n


def _percentage(lab: Lab, n: int) -> float:
    return 100 * random_blackjack(lab, n)


def _elapsed_time(lab: Lab) -> float:
    started = time.perf_counter()
    cartpole(lab)
    return time.perf_counter() - started


def _same_seed(lab: Lab) -> int:
    return _episode_length(lab.make("CartPole-v0"), velocity_policy, seed=42)


def _step_after_done(lab: Lab) -> int:
    env = lab.make("CartPole-v0")
    observation, _ = env.reset()
    steps, done = 0, False
    for _ in range(200):
        steps += 0 if done else 1
        observation, _, terminated, truncated, _ = env.step(velocity_policy(observation))
        done = done or terminated or truncated
    return steps


def _counts_steps_after_done(lab: Lab) -> int:
    env = lab.make("CartPole-v0")
    observation, _ = env.reset()
    for _ in range(200):  # counts every step, those after the pole fell too
        observation, _, _, _, _ = env.step(velocity_policy(observation))
    return 200


def _sticks_after_bust(lab: Lab, n: int, games: int = BLACKJACK_GAMES) -> float:
    # A real pattern: hit while the hand is <= n, then an unconditional stick (after a bust too).
    env = lab.make("Blackjack-v0")
    wins = 0
    for _ in range(games):
        observation, _ = env.reset()
        while observation[0] <= n:
            observation, _, _, _, _ = env.step(1)
        _, reward, _, _, _ = env.step(0)
        wins += reward > 0
    return wins / games


def _coin_hits_after_bust(lab: Lab, n: int) -> float:
    # A real pattern: hit while a coin says so (a busted hand too), then stick; a bust never becomes a win.
    env = lab.make("Blackjack-v0")
    wins = 0
    for _ in range(n):
        env.reset()
        while env.action_space.sample():
            env.step(1)
        _, reward, _, _, _ = env.step(0)
        wins += reward > 0
    return wins / n


def _sticks_first(lab: Lab, n: int, games: int = BLACKJACK_GAMES) -> float:
    # Sticks at once, then plays the threshold rule on the finished game: the games played ignore n.
    env = lab.make("Blackjack-v0")
    wins = 0
    for _ in range(games):
        observation, _ = env.reset()
        observation, reward, _, _, _ = env.step(0)
        while observation[0] <= n:
            observation, _, _, _, _ = env.step(1)
        wins += reward > 0  # the stick's reward: the right count of the games played
    return wins / games


def _strategy_not_random(lab: Lab, n: int) -> float:
    env = lab.make("Blackjack-v0")

    def policy(observation: Any, _step: int) -> int:
        return 1 if observation[0] <= 11 else int(env.action_space.sample())

    rewards = [_play_blackjack(env, policy) for _ in range(n)]
    return sum(reward > 0 for reward in rewards) / n


def _randint_always_stands(lab: Lab, n: int) -> float:
    env = lab.make("Blackjack-v0")
    # np.random.randint(0, 1) is always 0: the upper bound is exclusive.
    rewards = [_play_blackjack(env, lambda _observation, _step: 0) for _ in range(n)]
    return sum(reward > 0 for reward in rewards) / n


def _never_reaches(lab: Lab) -> int:
    return _episode_length(lab.make("MountainCar-v0"), lambda _observation: 2)


def _reset_after_make(lab: Lab) -> int:
    # A real pattern: the lab's "initialize, then reset" before the function's own reset.
    env = lab.make("CartPole-v0")
    env.reset()
    return _episode_length(env, velocity_policy)


def _reset_at_loop_end(lab: Lab, n: int) -> float:
    # A real pattern: reset before the loop and again at the end of every game (the last one unplayed).
    env = lab.make("Blackjack-v0")
    env.reset()
    wins = 0
    for _ in range(n):
        done, reward = False, 0.0
        while not done:
            _, reward, terminated, truncated, _ = env.step(int(env.action_space.sample()))
            done = terminated or truncated
        wins += reward > 0
        env.reset()
    return wins / n


def _scouting(lab: Lab) -> int:
    # Resets until the car starts far left (more room to swing), then one blind tape of pushes.
    env = lab.make("MountainCar-v0")
    observation, _ = env.reset()
    while observation[0] > -0.55:
        observation, _ = env.reset()
    steps, done = 0, False
    for action in [0] * 30 + [2] * 170:
        _, _, terminated, truncated, _ = env.step(action)
        steps, done = steps + 1, terminated or truncated
        if done:
            break
    return steps


def _chosen_start(lab: Lab) -> int:
    env = lab.make("MountainCar-v0")
    env.reset(options={"low": 0.55, "high": 0.55})
    steps, done = 0, False
    while not done:
        _, _, terminated, truncated, _ = env.step(2)
        steps, done = steps + 1, terminated or truncated
    return steps


@dataclass(frozen=True)
class Behaviour:
    """A simulated student for one problem.

    Attributes:
        name: Identifier (the matching sample is ``submissions/mistakes/<name>.py`` for most mistakes;
            the reset patterns and attacks of issue 8 have theirs in ``submissions/hostile/``).
        problem: The problem it is about.
        functions: Simulated functions by name.
        status: The status the checks must give it.
        feedback: A substring the feedback must contain ("" for none).
    """

    name: str
    problem: ProblemId
    functions: dict[str, StudentFunction]
    status: Status
    feedback: str = ""


REFERENCE: dict[ProblemId, dict[str, StudentFunction]] = {
    "random_blackjack": {"random_blackjack": random_blackjack},
    "blackjack": {"blackjack": blackjack},
    "cartpole": {"cartpole": cartpole},
    "car": {"car": car},
    "taxi": {"taxi": taxi},
}

MISTAKES: tuple[Behaviour, ...] = (
    Behaviour("blackjack_less_than", "blackjack", {"blackjack": _less_than}, "failed", "`<` versus `<=`"),
    Behaviour("blackjack_stale_hand", "blackjack", {"blackjack": _stale_hand}, "failed", "first decision"),
    Behaviour(
        "blackjack_v1",
        "blackjack",
        {"blackjack": partial(blackjack, env_id="Blackjack-v1")},
        "passed",
        "Blackjack-v1 (Sutton and Barto's rules, sab=True",
    ),
    Behaviour(
        "random_blackjack_v1",
        "random_blackjack",
        {"random_blackjack": partial(random_blackjack, env_id="Blackjack-v1")},
        "passed",
        "games of Blackjack-v1",
    ),
    Behaviour(
        "random_blackjack_not_random",
        "random_blackjack",
        {"random_blackjack": _strategy_not_random},
        "failed",
        "random actions",
    ),
    Behaviour(
        "random_blackjack_randint",
        "random_blackjack",
        {"random_blackjack": _randint_always_stands},
        "failed",
        "random actions draw a card in half of all decisions",
    ),
    Behaviour(
        "random_blackjack_average_reward",
        "random_blackjack",
        {"random_blackjack": _average_reward},
        "failed",
        "average reward",
    ),
    Behaviour(
        "random_blackjack_percentage",
        "random_blackjack",
        {"random_blackjack": _percentage},
        "passed",
        "read as a percentage",
    ),
    Behaviour("cartpole_elapsed_time", "cartpole", {"cartpole": _elapsed_time}, "failed", "elapsed time"),
    Behaviour("cartpole_same_seed", "cartpole", {"cartpole": _same_seed}, "failed", "not independent"),
    Behaviour(
        "cartpole_step_after_done",
        "cartpole",
        {"cartpole": _step_after_done},
        "passed",
        "kept stepping after the game was over",
    ),
    Behaviour(
        "cartpole_counts_steps_after_done",
        "cartpole",
        {"cartpole": _counts_steps_after_done},
        "failed",
        "kept stepping after the game was over and counted those",
    ),
    Behaviour(
        "blackjack_sticks_after_bust",
        "blackjack",
        {"blackjack": _sticks_after_bust},
        "passed",
        "kept stepping after the game was over",
    ),
    Behaviour(
        "random_blackjack_coin_hits_after_bust",
        "random_blackjack",
        {"random_blackjack": _coin_hits_after_bust},
        "passed",
        "kept stepping after the game was over",
    ),
    Behaviour(
        "blackjack_sticks_first",
        "blackjack",
        {"blackjack": _sticks_first},
        "failed",
        "draw while the sum is <= 12",
    ),
    Behaviour(
        "cartpole_v1",
        "cartpole",
        {"cartpole": partial(cartpole, env_id="CartPole-v1")},
        "passed",
        "CartPole-v1",
    ),
    Behaviour(
        "cartpole_random_step_first",
        "cartpole",
        {"cartpole": partial(_random_step_first, env_id="CartPole-v0", policy=velocity_policy)},
        "passed",
        "is one step short of its replayed episode",
    ),
    Behaviour(
        "cartpole_counted_from_one", "cartpole", {"cartpole": _counted_from_one}, "failed", "off by one"
    ),
    Behaviour("car_never_reaches_goal", "car", {"car": _never_reaches}, "failed", "ran out of time"),
    Behaviour("cartpole_reset_after_make", "cartpole", {"cartpole": _reset_after_make}, "passed"),
    Behaviour(
        "random_blackjack_reset_at_loop_end",
        "random_blackjack",
        {"random_blackjack": _reset_at_loop_end},
        "passed",
    ),
    Behaviour("car_scouting", "car", {"car": _scouting}, "failed", "not a fair sample of the starts dealt"),
    Behaviour("car_reset_options", "car", {"car": _chosen_start}, "failed", "call reset() without options"),
    Behaviour(
        "car_random_step_first",
        "car",
        {"car": partial(_random_step_first, env_id="MountainCar-v0", policy=car_policy)},
        "passed",
        "is one step short of its replayed episode",
    ),
    Behaviour("taxi_final_reward", "taxi", {"taxi": partial(taxi, final_only=True)}, "failed", "LAST reward"),
    Behaviour("taxi_v2", "taxi", {"taxi": partial(taxi, env_id="Taxi-v2")}, "error", "Taxi-v3"),
    Behaviour(
        "taxi_ignores_truncated",
        "taxi",
        {"taxi": _taxi_ignoring_truncation},
        "failed",
        "a loop that waits for `terminated` alone ignores the 200-step limit",
    ),
)
