"""`python -m reference`: run every reference solution once at the lab's sizes, then print the oracle table.

Takes about 30 seconds, most of it `taxi()` training its own Q-table (100 000 episodes) and playing
10 000 random episodes. `--quick` (about 3 seconds) gives `taxi()` the exact optimal Q-table instead of
training one and plays 1 000 episodes of each kind; every other solution runs at the lab's size.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable, Sequence
from functools import partial

from reference import solutions
from reference.oracles.table import build_oracle_table, format_oracle_table
from reference.oracles.taxi import optimal_q_table

QUICK_TAXI_EPISODES = 1_000


def main(argv: Sequence[str] | None = None) -> int:
    """Run the reference solutions and print their results next to the exact oracle table."""
    parser = argparse.ArgumentParser(prog="python -m reference", description=__doc__)
    parser.add_argument("--seed", type=int, default=None, help="seed every run (default: fresh randomness)")
    parser.add_argument("--quick", action="store_true", help="taxi() on the optimal Q-table, 1 000 episodes")
    args = parser.parse_args(argv)
    seed = args.seed
    if args.quick:
        taxi_call = f"taxi(Q*, episodes={QUICK_TAXI_EPISODES})"
        taxi_run = partial(solutions.taxi, optimal_q_table(), episodes=QUICK_TAXI_EPISODES, seed=seed)
    else:
        taxi_call, taxi_run = "taxi()", partial(solutions.taxi, seed=seed)
    runs: list[tuple[str, str, Callable[[], object]]] = [
        ("random_blackjack(500)", "fraction won", partial(solutions.random_blackjack, 500, seed=seed)),
        ("blackjack(11)", "fraction won", partial(solutions.blackjack, 11, seed=seed)),
        ("cartpole()", "steps", partial(solutions.cartpole, seed=seed)),
        ("car()", "steps", partial(solutions.car, seed=seed)),
        (taxi_call, "(random, Q-table) mean total reward", taxi_run),
    ]
    print("Reference solutions, one run each" + (" (--quick)" if args.quick else " at the lab's sizes"))
    for call, meaning, run in runs:
        start = time.perf_counter()
        value = run()
        shown = tuple(round(part, 4) for part in value) if isinstance(value, tuple) else value
        print(f"  {call:<27} {meaning}: {shown}   [{time.perf_counter() - start:.1f} s]", flush=True)
    print()
    print(format_oracle_table(build_oracle_table()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
