"""Replay cost: replaying logged episodes in the parent against the student's own run time.

The main figure: the lab's cartpole (classic `gym` API, the reference policy "push the way the
pole's tip moves") is called 100 times in the child harness (a plain subprocess over the real
protocol, no isolation: isolation does not change the time spent inside the function). The
student's own run time is the sum of the calls' `wall_time` (time inside the student's function,
recorder included). The replay cost is the time `replay_episodes` takes on the 100 logs (batched),
and, for comparison, replaying them one at a time with `replay_episode`. Medians and minima over
`--rounds` rounds; each round's replay time is the best of 3 repeats. A second table does the same
for one call playing `--taxi-episodes` random Taxi episodes (the lab's problem 5 plays 10 000), a third
for one call of the lab's `blackjack(11)` playing `--blackjack-games` games (problem 2 plays 10 000).

    python bench/replay.py [--rounds 7] [--taxi-episodes 500] [--blackjack-games 10000]
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from grader.sandbox.child import frames
from grader.sandbox.episode_log import EpisodeLog, episodes_from_plain
from grader.sandbox.replay import replay_episode, replay_episodes

HARNESS = Path(__file__).resolve().parents[1] / "grader" / "sandbox" / "child" / "__main__.py"
CARTPOLE_CALLS = 100
LAB_SUBMISSION = textwrap.dedent("""
    import gym


    def cartpole():
        env = gym.make("CartPole-v0")
        try:
            observation = env.reset()
            done, steps = False, 0
            while not done:
                observation, reward, done, info = env.step(1 if observation[3] > 0 else 0)
                steps += 1
            return steps
        finally:
            env.close()


    def random_taxi(episodes):
        env = gym.make("Taxi-v3")
        total = 0
        for _ in range(episodes):
            env.reset()
            done = False
            while not done:
                _, reward, done, _ = env.step(env.action_space.sample())
                total += reward
        return total / episodes


    def blackjack(n, games):
        env = gym.make("Blackjack-v0")
        wins = 0
        for _ in range(games):
            observation = env.reset()
            done = False
            while not done:
                observation, reward, done, _ = env.step(1 if observation[0] <= n else 0)
            wins += reward > 0
        return wins / games
""")


@dataclass(frozen=True)
class ReplayCost:
    """Seconds for one workload: (median, minimum) over the rounds."""

    student_seconds: tuple[float, float]
    batched_replay_seconds: tuple[float, float]
    scalar_replay_seconds: tuple[float, float]
    steps: int
    student_cpu_seconds: tuple[float, float]
    batched_replay_cpu_seconds: tuple[float, float]

    @property
    def batched_fraction(self) -> tuple[float, float]:
        """Batched replay time as a fraction of the student's own run time (median, minimum)."""
        return _ratios(self.batched_replay_seconds, self.student_seconds)

    @property
    def batched_cpu_fraction(self) -> tuple[float, float]:
        """Batched replay CPU time over the student's CPU time (the child's, minus its import)."""
        return _ratios(self.batched_replay_cpu_seconds, self.student_cpu_seconds)

    @property
    def scalar_fraction(self) -> tuple[float, float]:
        """One-at-a-time replay time as a fraction of the student's own run time (median, minimum)."""
        return _ratios(self.scalar_replay_seconds, self.student_seconds)


def play(function: str, args: list[Any], calls: int, seed: int) -> tuple[float, float, list[EpisodeLog]]:
    """Call `function(*args)` `calls` times in one child.

    Returns:
        The summed `wall_time` of the calls, the child's whole CPU time (user + system, import
        included) and the episode logs.
    """
    with tempfile.TemporaryDirectory() as directory:
        submission = Path(directory) / "submission.py"
        submission.write_text(LAB_SUBMISSION)
        requests_read, requests_write = os.pipe()
        results_read, results_write = os.pipe()
        command = [
            sys.executable,
            "-I",
            "-B",
            str(HARNESS),
            "--submission",
            str(submission),
            "--requests",
            str(requests_read),
            "--results",
            str(results_write),
        ]
        child = subprocess.Popen(command, pass_fds=(requests_read, results_write), stdin=subprocess.DEVNULL)
        os.close(requests_read)
        os.close(results_write)
        wall_time, logs = 0.0, []
        with os.fdopen(results_read, "rb") as results:
            ready = frames.read_frame(results)
            if ready is None or ready["type"] != "ready":
                raise RuntimeError(f"the harness did not start: {ready}")
            for call in range(calls):
                frame = {
                    "type": "call",
                    "id": call,
                    "nonce": "bench",
                    "function": function,
                    "args": args,
                    "kwargs": {},
                    "seed": seed * calls + call,
                    "record": True,
                }
                frames.write_frame(requests_write, frame)
                result = frames.read_frame(results)
                if result is None or result["status"] != "ok":
                    raise RuntimeError(f"call {call} failed: {result}")
                wall_time += result["wall_time"]
                logs += episodes_from_plain(result["episodes"])
        os.close(requests_write)
        _, _, usage = os.wait4(child.pid, 0)
        child.returncode = 0
    return wall_time, usage.ru_utime + usage.ru_stime, logs


def measure_replay_cost(
    rounds: int = 7, *, function: str = "cartpole", args: list[Any] | None = None, calls: int = CARTPOLE_CALLS
) -> ReplayCost:
    """Measure the replay cost over `rounds` independent runs (fresh child, new seeds each round).

    Defaults to the main figure: 100 calls of the lab's cartpole. The replay envs are cached after
    the first repeat, as they are when a grading run replays many calls.
    """
    import_cpu = statistics.median(play(function, args or [], 0, 0)[1] for _ in range(3))
    student, student_cpu, batched, batched_cpu, scalar, steps = [], [], [], [], [], 0
    for round_number in range(rounds):
        wall_time, cpu_time, logs = play(function, args or [], calls, round_number)
        if not all(replay.matches for replay in replay_episodes(logs)):
            raise RuntimeError("an honest episode did not replay identically")
        student.append(wall_time)
        student_cpu.append(max(cpu_time - import_cpu, 1e-9))
        batched.append(_best_of(lambda logs=logs: replay_episodes(logs)))  # type: ignore[misc]
        batched_cpu.append(_best_of(lambda logs=logs: replay_episodes(logs), clock=time.process_time))  # type: ignore[misc]
        scalar.append(_best_of(lambda logs=logs: [replay_episode(log) for log in logs]))  # type: ignore[misc]
        steps = sum(log.steps for log in logs)
    return ReplayCost(
        _summary(student),
        _summary(batched),
        _summary(scalar),
        steps,
        _summary(student_cpu),
        _summary(batched_cpu),
    )


def _ratios(part: tuple[float, float], whole: tuple[float, float]) -> tuple[float, float]:
    return part[0] / whole[0], part[1] / whole[1]


def _summary(samples: list[float]) -> tuple[float, float]:
    return statistics.median(samples), min(samples)


def _best_of(
    function: Callable[[], object], repeats: int = 3, clock: Callable[[], float] = time.perf_counter
) -> float:
    best = math.inf
    for _ in range(repeats):
        started = clock()
        function()
        best = min(best, clock() - started)
    return best


def _print(title: str, cost: ReplayCost) -> None:
    print(f"{title} ({cost.steps} steps in the last round), median / minimum:")
    rows = [
        ("student's own run time (sum of wall_time)", cost.student_seconds, None),
        ("replay_episodes (batched)", cost.batched_replay_seconds, cost.batched_fraction),
        ("replay_episode one at a time", cost.scalar_replay_seconds, cost.scalar_fraction),
        ("CPU: student's calls (child minus its import)", cost.student_cpu_seconds, None),
        ("CPU: replay_episodes (batched)", cost.batched_replay_cpu_seconds, cost.batched_cpu_fraction),
    ]
    for label, (median, minimum), fraction in rows:
        share = "" if fraction is None else f"  = {fraction[0]:6.1%} / {fraction[1]:6.1%} of the student's"
        print(f"  {label:<46} {median * 1000:8.1f} / {minimum * 1000:8.1f} ms{share}")


def main() -> None:
    """Print the figures for bench/RESULTS.md."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--taxi-episodes", type=int, default=500)
    parser.add_argument("--blackjack-games", type=int, default=10_000)
    arguments = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs")
    _print(
        f"{CARTPOLE_CALLS} calls of the lab's cartpole, {arguments.rounds} rounds",
        measure_replay_cost(arguments.rounds),
    )
    print("  target: replay <= 10% of the student's own run time")
    taxi = measure_replay_cost(
        max(1, arguments.rounds // 2), function="random_taxi", args=[arguments.taxi_episodes], calls=1
    )
    _print(f"1 call playing {arguments.taxi_episodes} random Taxi episodes", taxi)
    blackjack = measure_replay_cost(
        max(1, arguments.rounds // 2), function="blackjack", args=[11, arguments.blackjack_games], calls=1
    )
    _print(f"1 call of the lab's blackjack(11) playing {arguments.blackjack_games} games", blackjack)
    print(f"load average after: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
