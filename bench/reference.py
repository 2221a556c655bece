"""Reference figures: the oracle table, the reference policies over many runs, and wall times.

Prints, as Markdown for bench/RESULTS.md (`## Reference`):

1. the exact oracle table (`python -m reference.oracles`);
2. the reference policies run 100 times (seeds 0..99, the lab's "run your function 100 times") and over
   2000 seeds: CartPole steps (mean, min), MountainCar steps (mean, max, and over a sweep of 2001 start
   positions), and Taxi: Q-tables trained by the reference `find_qvalues` (100 000 episodes, 3 seeds),
   each with the exact return of its greedy policy and the mean of 100 greedy episodes;
3. the wall time of each reference function next to the same function written literally as in the lab:
   `submissions/classic_complete.py` (classic `gym`) run through the compatibility layer
   (`grader.compat.activate()`), and `submissions/gymnasium_complete.py`, the same code ported
   line by line to gymnasium's API (no layer). One call each at the lab's sizes.

    python bench/reference.py            # about 5 minutes on one core
"""

from __future__ import annotations

import sys
from pathlib import Path

if sys.path and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    # `python bench/reference.py` puts bench/ first on sys.path, where this file would shadow the package.
    del sys.path[0]

import contextlib
import io
import platform
import runpy
import statistics
import time
from collections.abc import Callable
from typing import Any

import gymnasium as gym
import numpy as np

from reference import solutions
from reference.oracles.table import build_oracle_table, format_oracle_table
from reference.oracles.taxi import greedy_policy_return, optimal_q_table, optimal_return

ROOT = Path(__file__).resolve().parents[1]
RUNS = 100
MANY_SEEDS = 2_000
TRAINING_SEEDS = (0, 1, 2)


def _oracle_section() -> list[str]:
    return [
        "### Oracle table (`python -m reference.oracles`)",
        "",
        "```",
        format_oracle_table(build_oracle_table()),
        "```",
    ]


def _mountain_car_start_sweep(positions: int = 2_001) -> list[int]:
    """Steps to the flag from every start position in [-0.6, -0.4] (velocity 0, as reset draws it)."""
    steps = []
    with gym.make(solutions.MOUNTAIN_CAR_ID) as env:
        for position in np.linspace(-0.6, -0.4, positions):
            env.reset(seed=0)
            env.unwrapped.state = np.array([position, 0.0])  # type: ignore[attr-defined]
            observation = np.array([position, 0.0], dtype=np.float32)
            count, terminated, truncated = 0, False, False
            while not (terminated or truncated):
                observation, _, terminated, truncated, _ = env.step(
                    solutions.mountain_car_policy(observation)
                )
                count += 1
            steps.append(count if terminated else -count)
    return steps


def _policy_section() -> list[str]:
    lines = [
        "### Reference policies over many runs",
        "",
        "| figure | seeds 0..99 | seeds 0..1999 |",
        "|---|---|---|",
    ]
    cart_runs = [solutions.cartpole(seed=seed) for seed in range(MANY_SEEDS)]
    car_runs = [solutions.car(seed=seed) for seed in range(MANY_SEEDS)]
    for label, values, summary in [
        ("CartPole-v0 steps: mean / min", cart_runs, lambda v: f"{statistics.mean(v):.1f} / {min(v)}"),
        ("MountainCar-v0 steps: mean / max", car_runs, lambda v: f"{statistics.mean(v):.1f} / {max(v)}"),
    ]:
        lines.append(f"| {label} | {summary(values[:RUNS])} | {summary(values)} |")
    sweep = _mountain_car_start_sweep()
    reached = all(steps > 0 for steps in sweep)
    lines += [
        "",
        f"MountainCar from 2001 evenly spaced start positions in [-0.6, -0.4]: goal reached from every one: "
        f"{reached}; steps {min(map(abs, sweep))}..{max(map(abs, sweep))}, "
        f"mean {statistics.mean(map(abs, sweep)):.1f}.",
        "",
        f"Taxi-v4 (exact optimum within 200 steps: {optimal_return().mean:.4f}):",
        "",
        "| find_qvalues seed | training (wall) | exact greedy return (mean, std) | mean of 100 greedy runs |",
        "|---|---|---|---|",
    ]
    for seed in TRAINING_SEEDS:
        start = time.perf_counter()
        q_table = solutions.find_qvalues(solutions.TAXI_ID, seed=seed)
        training = time.perf_counter() - start
        exact = greedy_policy_return(q_table)
        _, greedy_mean = solutions.taxi(q_table, episodes=RUNS, seed=seed)
        lines.append(
            f"| {seed} | {training:.1f} s | {exact.mean:.4f} ({exact.std:.4f}) | {greedy_mean:.2f} |"
        )
    return lines


def _load(path: Path, *, through_compat: bool) -> dict[str, Any]:
    if through_compat:
        from grader.compat import activate

        activate()
    return runpy.run_path(str(path), run_name=path.stem)


def _timed(function: Callable[[], object]) -> str:
    """Wall time and, in parentheses, CPU time of one call (the cores are shared with other work)."""
    # The lab's find_qvalues prints 1000 progress lines; they are not part of the measurement's output.
    with contextlib.redirect_stdout(io.StringIO()):
        wall, cpu = time.perf_counter(), time.process_time()
        function()
        return f"{time.perf_counter() - wall:.2f} s ({time.process_time() - cpu:.2f} s)"


def _timing_section() -> list[str]:
    q_table = optimal_q_table()
    classic = _load(ROOT / "submissions" / "classic_complete.py", through_compat=True)
    ported = _load(ROOT / "submissions" / "gymnasium_complete.py", through_compat=False)
    rows: list[tuple[str, Callable[[], object], Callable[[], object], Callable[[], object]]] = [
        (
            "random_blackjack(500)",
            lambda: solutions.random_blackjack(500),
            lambda: classic["random_blackjack"](500),
            lambda: ported["random_blackjack"](500),
        ),
        ("blackjack(11), 10 000 games", solutions.blackjack, classic["blackjack"], ported["blackjack"]),
        (
            "cartpole() x 100",
            lambda: [solutions.cartpole() for _ in range(RUNS)],
            lambda: [classic["cartpole"]() for _ in range(RUNS)],
            lambda: [ported["cartpole"]() for _ in range(RUNS)],
        ),
        (
            "car() x 100",
            lambda: [solutions.car() for _ in range(RUNS)],
            lambda: [classic["car"]() for _ in range(RUNS)],
            lambda: [ported["car"]() for _ in range(RUNS)],
        ),
        (
            "find_qvalues, 100 000 episodes",
            lambda: solutions.find_qvalues(solutions.TAXI_ID),
            lambda: classic["find_qvalues"]("Taxi-v3"),
            lambda: ported["find_qvalues"]("Taxi-v4"),
        ),
        (
            "taxi(q_table), 2 x 10 000 episodes",
            lambda: solutions.taxi(q_table),
            lambda: classic["taxi"](q_table),
            lambda: ported["taxi"](q_table),
        ),
    ]
    lines = [
        "### Wall time (CPU time): reference against the lab-literal code (one call each)",
        "",
        "| function | reference | lab-literal (classic gym + grader.compat) | lab-literal (gymnasium port) |",
        "|---|---|---|---|",
    ]
    for label, reference_run, classic_run, ported_run in rows:
        lines.append(
            f"| {label} | "
            + " | ".join(_timed(run) for run in (reference_run, classic_run, ported_run))
            + " |"
        )
        print(lines[-1], file=sys.stderr, flush=True)
    return lines


def main() -> int:
    """Print the reference figures as Markdown."""
    started = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    lines = [
        f"Measured {started} by `python bench/reference.py` on {platform.processor() or platform.machine()}, "
        f"Python {platform.python_version()}, gymnasium {gym.__version__}, one process (2 shared cores).",
        "",
        *_oracle_section(),
        "",
        *_policy_section(),
        "",
        *_timing_section(),
    ]
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
