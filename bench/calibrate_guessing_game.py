"""Calibrate the optional guessing_game check: regrade the midpoint search and each mistake on fresh seeds.

Every regrade plans the check's calls (the bundled settings, the problem enabled), plays them in-process on
real GuessingGame-v0 games (`grader.simulated_students.simulation`), replays every game for real and judges
with the real check. Prints the reference's false-fail rate, each mistake's detection rate, and the exact
figures behind the statistic (`reference.oracles.guessing_game`).

    python bench/calibrate_guessing_game.py                # 200 regrades of the reference, 50 per mistake
    python bench/calibrate_guessing_game.py --regrades 20  # a smoke run
"""

from __future__ import annotations

import argparse
import sys
import time
import zlib
from collections import Counter
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from grader.compat import register_envs
from grader.lab.assignment import load_config
from grader.lab.checks.guessing_game import MIDPOINT_SLACK, GuessingGameConfig, total_acceptance
from grader.lab.problems import PROBLEMS
from grader.simulated_students.simulation import Lab, function_infos, simulate_calls
from reference.oracles.guessing_game import midpoint_guess_counts

Guesser = Callable[[float, float, int, Lab, Any], float]
"""(low, high, guesses made, lab, target shown by the last info or None) -> the next guess."""


def _play(
    lab: Lab, guesser: Guesser, *, margin: float = 0.0, counted_from: int = 0, bound: float = 1000.0
) -> int:
    env = lab.make("GuessingGame-v0")
    env.reset()
    low, high, guesses, done, target = -bound, bound, counted_from, False, None
    while not done:
        guess = guesser(low, high, guesses, lab, target)
        observation, _, terminated, truncated, info = env.step(np.array([guess]))
        guesses, done, target = guesses + 1, terminated or truncated, info["number"]
        if observation == 1:
            low = guess + margin
        elif observation == 3:
            high = guess - margin
    return guesses


def _midpoint(low: float, high: float, _made: int, _lab: Lab, _target: Any) -> float:
    return (low + high) / 2


def _leaning(low: float, high: float, _made: int, _lab: Lab, target: Any) -> float:
    middle = (low + high) / 2
    return middle if target is None else middle + float(np.sign(target - middle)) * (MIDPOINT_SLACK - 0.01)


BEHAVIOURS: dict[str, tuple[Callable[[Lab], int], str, str]] = {
    "reference: midpoint search": (lambda lab: _play(lab, _midpoint), "passed", "every guess the midpoint"),
    "integer midpoints, ends moved past the guess by 1": (
        lambda lab: _play(lab, lambda low, high, *_: (low + high) // 2, margin=1.0),
        "passed",
        "every guess the midpoint",
    ),
    "ends moved past the guess by the tolerance (10)": (
        lambda lab: _play(lab, _midpoint, margin=10.0),
        "passed",
        "every guess the midpoint",
    ),
    "linear search, steps of 20": (
        lambda lab: _play(lab, lambda low, _high, *_: low + 20),
        "failed",
        "a linear search",
    ),
    "random guesses in [-10000, 10000]": (
        lambda lab: _play(lab, lambda _low, _high, _made, lab, _target: lab.random.uniform(-10_000, 10_000)),
        "failed",
        "as random guesses would",
    ),
    "midpoint search from the guess space [-10000, 10000]": (
        lambda lab: _play(lab, _midpoint, bound=10_000.0),
        "failed",
        "the guess space",
    ),
    "counts only the misses (1 short)": (
        lambda lab: _play(lab, _midpoint, counted_from=-1),
        "failed",
        "off by one",
    ),
    "counts one guess too many": (lambda lab: _play(lab, _midpoint, counted_from=1), "failed", "off by one"),
    "leans toward info['number'] within the tolerance": (
        lambda lab: _play(lab, _leaning),
        "failed",
        "the guesses used something the observations do not say",
    ),
}
"""Behaviour -> (simulated guessing_game, the status it must get, a substring its feedback must contain)."""


def _settings() -> GuessingGameConfig:
    settings = load_config().problems["guessing_game"]
    if not isinstance(settings, GuessingGameConfig):
        raise TypeError(f"expected the guessing_game settings, found {type(settings).__name__}")
    return settings.model_copy(update={"enabled": True})


def regrade(behaviour: str, index: int, settings: GuessingGameConfig) -> tuple[bool, str, float]:
    """One regrade on a seed derived from (behaviour, index): (as expected, status, seconds)."""
    student, expected, feedback = BEHAVIOURS[behaviour]
    functions = {"guessing_game": student}
    check = PROBLEMS.problem("guessing_game").check
    started = time.perf_counter()
    calls = check.plan(settings, function_infos(functions), 0)
    seed = zlib.crc32(behaviour.encode()) * 1_000_003 + index
    verdict = check.judge(settings, simulate_calls(calls, functions, seed, replay=True))
    matched = verdict.status == expected and feedback in verdict.feedback
    return matched, verdict.status, time.perf_counter() - started


def calibration_table(regrades: int, mistake_regrades: int) -> str:
    """Markdown: per behaviour, regrades, expected status, how often it was given, seconds per regrade."""
    settings = _settings()
    lines = [
        "| behaviour | expected | regrades | as expected | rate | other outcomes | s/regrade |",
        "|---|---|---:|---:|---:|---|---:|",
    ]
    for behaviour, (_, expected, _) in BEHAVIOURS.items():
        count = regrades if expected == "passed" else mistake_regrades
        results = [regrade(behaviour, index, settings) for index in range(count)]
        matched = sum(result[0] for result in results)
        others = Counter(result[1] for result in results if not result[0])
        other_text = ", ".join(f"{status} x{n}" for status, n in others.items()) or "-"
        seconds = sum(result[2] for result in results) / count
        lines.append(
            f"| {behaviour} | {expected} | {count} | {matched} | {matched / count:.3f} | {other_text} | "
            f"{seconds:.2f} |"
        )
    return "\n".join(lines)


def exact_figures() -> str:
    """The oracle's distribution and the acceptance of the configured test, as Markdown."""
    settings = _settings()
    counts = midpoint_guess_counts()
    wide = midpoint_guess_counts(-10_000, 10_000)
    acceptance = total_acceptance(settings.calls, settings.count_alpha)
    distribution = ", ".join(f"{k}: {p:g}" for k, p in enumerate(counts.probabilities, 1))
    return (
        f"- Guesses per game of the midpoint search from [-1000, 1000] (exact): {distribution}; mean "
        f"{counts.mean:.6g}, standard deviation {counts.variance**0.5:.6g}. From the guess space "
        f"[-10000, 10000]: mean {wide.mean:.6g}.\n"
        f"- The test: {acceptance.games} games, accepted total {acceptance.low} to {acceptance.high} "
        f"(mean {acceptance.low / acceptance.games:.2f} to {acceptance.high / acceptance.games:.2f}), exact "
        f"false-fail probability {acceptance.false_fail:.3g} (count_alpha {settings.count_alpha:g})."
    )


def main(argv: Sequence[str] | None = None) -> int:
    """Print the exact figures and the calibration table."""
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--regrades", type=int, default=200, help="regrades of each passing behaviour")
    parser.add_argument("--mistake-regrades", type=int, default=50, help="regrades of each mistake")
    arguments = parser.parse_args(argv)
    register_envs()
    started = time.perf_counter()
    print(exact_figures())
    print()
    print(calibration_table(arguments.regrades, arguments.mistake_regrades))
    print(f"\n({time.perf_counter() - started:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
