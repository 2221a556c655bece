"""A mutation run of the verdict logic: does a green suite prove what it seems to? (issue 34)

Each mutant is one small change to the code that decides a verdict (grader/lab/checks/) or to the rules of
a compatibility game (grader/compat/envs/): a statistical decision forced to accept, a comparison flipped,
a diagnosis branch removed, a game rule changed. Every mutant is applied alone to a temporary copy of the
worktree, the fast tests that cover that code run there (`python -m pytest -x`), and the mutant is
`killed` when they fail, `survived` when they pass. A surviving mutant is a change the tests cannot see.

    python bench/mutation.py                    # every mutant, prints the table
    python bench/mutation.py --only taxi        # the mutants whose name contains "taxi" (--only repeats)
    python bench/mutation.py --write            # and records the table in bench/RESULTS.md
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.results_section import replace_section

ROOT = Path(__file__).resolve().parents[1]
HEADING = "## Mutation run of the verdict logic (issue 34)"
CHECKS = "grader/lab/checks"
CHECK_TESTS = "tests/grader/lab/checks"
TIMEOUT = 900


@dataclass(frozen=True)
class Mutant:
    """One change: `old` (which must occur exactly once in `path`) replaced by `new`."""

    name: str
    path: str
    old: str
    new: str
    tests: tuple[str, ...]
    """pytest arguments: the test files (and -k) that cover the changed code."""


def _students(expression: str) -> tuple[str, ...]:
    return (f"{CHECK_TESTS}/test_students.py", "-k", expression)


RANDOM_BLACKJACK = (f"{CHECK_TESTS}/test_random_blackjack.py", *_students("random_blackjack"))
BLACKJACK = (f"{CHECK_TESTS}/test_blackjack.py", *_students("blackjack and not random_blackjack"))
TAXI = (f"{CHECK_TESTS}/test_taxi.py", *_students("taxi"))
TOY_TEXT = ("tests/grader/compat/envs/test_toy_text.py",)


def _never(name: str, path: str, condition: str, tests: tuple[str, ...], *, then: str = "") -> Mutant:
    """The branch `if <condition>:<then>` removed (its condition made False); `then` tells apart branches
    with the same condition."""
    return Mutant(name, path, f"if {condition}:{then}", f"if False:{then}", tests)


_RB = f"{CHECKS}/random_blackjack.py"
_BJ = f"{CHECKS}/blackjack.py"
_TX = f"{CHECKS}/taxi.py"
_RO = "grader/compat/envs/roulette.py"
_KE = "grader/compat/envs/kelly_coinflip.py"

MUTANTS: tuple[Mutant, ...] = (
    # random_blackjack: every diagnosis branch, each comparison, the three statistical decisions.
    _never("random_blackjack: not a number", _RB, "returned is None", RANDOM_BLACKJACK),
    _never(
        "random_blackjack: integrity",
        _RB,
        "problem",
        RANDOM_BLACKJACK,
        then='\n            return _fail(f"{call}: {problem}.")',
    ),
    _never("random_blackjack: game count", _RB, "counts.games != settings.games", RANDOM_BLACKJACK),
    Mutant(
        "random_blackjack: game count flipped",
        _RB,
        "counts.games != settings.games",
        "counts.games == settings.games",
        RANDOM_BLACKJACK,
    ),
    _never("random_blackjack: rate not the replay's", _RB, "scale is None", RANDOM_BLACKJACK),
    _never(
        "random_blackjack: hit frequency accepts", _RB, "not frequency.accepts(hit_share)", RANDOM_BLACKJACK
    ),
    _never(
        "random_blackjack: independence accepts",
        _RB,
        "by_sum.p_value < settings.action_alpha",
        RANDOM_BLACKJACK,
    ),
    Mutant(
        "random_blackjack: independence flipped",
        _RB,
        "by_sum.p_value < settings.action_alpha",
        "by_sum.p_value > settings.action_alpha",
        RANDOM_BLACKJACK,
    ),
    _never(
        "random_blackjack: win count accepts", _RB, "not acceptance.accepts(counts.wins)", RANDOM_BLACKJACK
    ),
    Mutant(
        "random_blackjack: win count flipped",
        _RB,
        "if not acceptance.accepts(counts.wins):",
        "if acceptance.accepts(counts.wins):",
        RANDOM_BLACKJACK,
    ),
    # blackjack
    _never(
        "blackjack: integrity",
        _BJ,
        "problem",
        BLACKJACK,
        then='\n            return Verdict("failed", 0.0, f"blackjack: {problem}.", {})',
    ),
    _never("blackjack: not a number", _BJ, "returned is None", BLACKJACK),
    _never(
        "blackjack: repeated seeds",
        _BJ,
        "problem",
        BLACKJACK,
        then='\n            return f"{call}: {problem}.", ""',
    ),
    _never("blackjack: game count", _BJ, "counts.games != settings.games_per_call", BLACKJACK),
    _never("blackjack: rate not the replay's", _BJ, "scale is None", BLACKJACK),
    _never("blackjack: rule deviation", _BJ, "deviation", BLACKJACK),
    Mutant(
        "blackjack: rule '<=' read as '<'",
        _BJ,
        "wrong = [decision for decision in decisions if decision.hit != (decision.total <= n)]",
        "wrong = [decision for decision in decisions if decision.hit != (decision.total < n)]",
        BLACKJACK,
    ),
    _never("blackjack: win count accepts", _BJ, "not acceptance.accepts(counts.wins)", BLACKJACK),
    Mutant(
        "blackjack: win count flipped",
        _BJ,
        "if not acceptance.accepts(counts.wins):",
        "if acceptance.accepts(counts.wins):",
        BLACKJACK,
    ),
    _never(
        "blackjack: a failing call",
        _BJ,
        "first_failure",
        BLACKJACK,
        then="\n            return",
    ),
    # taxi
    _never("taxi: not two numbers", _TX, "None in means", TAXI),
    _never(
        "taxi: integrity",
        _TX,
        "problem",
        TAXI,
        then="\n            # An altered",
    ),
    _never(
        "taxi: no split",
        _TX,
        "scenarios is None",
        TAXI,
        then="\n            # Steps",
    ),
    _never("taxi: episode count", _TX, "len(scenario) != settings.episodes_per_scenario", TAXI),
    _never("taxi: random actions uniform", _TX, "uniform.p_value < settings.action_alpha", TAXI),
    _never("taxi: greedy on the given table", _TX, "action != best", TAXI),
    Mutant(
        "taxi: one action per state",
        _TX,
        "elif chosen.setdefault(state, action) != action:",
        "elif False:",
        TAXI,
    ),
    _never("taxi: random mean accepts", _TX, "not random_test.accepts(random_mean)", TAXI),
    Mutant(
        "taxi: random mean flipped",
        _TX,
        "if not random_test.accepts(random_mean):",
        "if random_test.accepts(random_mean):",
        TAXI,
    ),
    Mutant(
        "taxi: given table's mean accepts",
        _TX,
        "greedy_ok = greedy_test.accepts(greedy_mean)",
        "greedy_ok = True",
        TAXI,
    ),
    Mutant("taxi: trained floor accepts", _TX, "greedy_ok = greedy_mean >= floor", "greedy_ok = True", TAXI),
    Mutant(
        "taxi: trained floor flipped",
        _TX,
        "greedy_ok = greedy_mean >= floor",
        "greedy_ok = greedy_mean <= floor",
        TAXI,
    ),
    Mutant(
        "taxi: Q beats random dropped",
        _TX,
        "if not greedy_ok or greedy_mean <= random_mean:",
        "if not greedy_ok:",
        TAXI,
    ),
    # the other statistical decisions of the checks, forced to accept
    Mutant(
        "compare: means accept",
        f"{CHECKS}/compare.py",
        "if not all(test.accepts(mean) for test, mean in zip(tests, expected, strict=True)):",
        "if False:",
        (f"{CHECK_TESTS}/test_compare.py",),
    ),
    Mutant(
        "guessing_game: guess total accepts",
        f"{CHECKS}/guessing_game.py",
        "if not acceptance.accepts(total):",
        "if False:",
        (f"{CHECK_TESTS}/test_guessing_game.py",),
    ),
    Mutant(
        "taxi_tables: means accept",
        f"{CHECKS}/taxi_tables.py",
        "if not (tests[0].accepts(first) and tests[1].accepts(second)):",
        "if False:",
        (f"{CHECK_TESTS}/test_taxi_tables.py",),
    ),
    Mutant(
        "starts: selection accepts",
        f"{CHECKS}/starts.py",
        "return self.p_value <= self.threshold",
        "return False",
        (f"{CHECK_TESTS}/test_starts.py",),
    ),
    # the toy-text compatibility games' rules
    Mutant("roulette: zero pays spots - 1", _RO, "reward = self.n - 2.0", "reward = self.n - 1.0", TOY_TEXT),
    Mutant(
        "roulette: parity flipped",
        _RO,
        "value % 2 == action % 2",
        "value % 2 != action % 2",
        TOY_TEXT,
    ),
    Mutant(
        "kelly: coin wins with 1 - edge",
        _KE,
        "won = bool(np_random.uniform() < edge)",
        "won = bool(np_random.uniform() > edge)",
        TOY_TEXT,
    ),
    Mutant(
        "kelly: no wealth cap",
        _KE,
        "return min(cap, wealth + (bet if won else -bet))",
        "return wealth + (bet if won else -bet)",
        TOY_TEXT,
    ),
    Mutant(
        "kelly: prior Beta(3, 7)",
        _KE,
        "edge = float(self.np_random.beta(*self.edge_prior))",
        "edge = float(self.np_random.beta(*self.edge_prior[::-1]))",
        TOY_TEXT,
    ),
    Mutant(
        "kelly: a level round counts as a loss",
        _KE,
        "if self.wealth >= before:",
        "if self.wealth > before:",
        TOY_TEXT,
    ),
)


def _copy(destination: Path) -> Path:
    ignored = shutil.ignore_patterns(
        ".git", ".venv", "__pycache__", ".mypy_cache", ".ruff_cache", ".pytest_cache", "node_modules"
    )
    shutil.copytree(ROOT, destination, ignore=ignored)
    return destination


def _run_tests(copy: Path, tests: tuple[str, ...]) -> tuple[int, float]:
    environment = {**os.environ, "PYTHONPATH": str(copy), "PYTHONDONTWRITEBYTECODE": "1"}
    started = time.perf_counter()
    try:
        completed = subprocess.run(
            [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", *tests],
            cwd=copy,
            env=environment,
            capture_output=True,
            timeout=TIMEOUT,
            check=False,
        )
        code = completed.returncode
    except subprocess.TimeoutExpired:
        code = -1
    return code, time.perf_counter() - started


def run(mutants: list[Mutant]) -> list[tuple[Mutant, str, float]]:
    """Apply each mutant alone to a temporary copy, run its tests, and say whether they killed it."""
    results = []
    with tempfile.TemporaryDirectory(prefix="gymgrade-mutation-") as directory:
        copy = _copy(Path(directory) / "tree")
        probe = subprocess.run(
            [sys.executable, "-c", "import grader; print(grader.__file__)"],
            cwd=copy,
            capture_output=True,
            text=True,
            check=True,
        )
        if not probe.stdout.strip().startswith(str(copy)):
            raise SystemExit(f"the copy's tests would import {probe.stdout.strip()}, not the copy's grader")
        for mutant in mutants:
            target = copy / mutant.path
            original = target.read_text(encoding="utf-8")
            if original.count(mutant.old) != 1:
                raise SystemExit(f"{mutant.name}: expected one {mutant.old!r} in {mutant.path}")
            target.write_text(original.replace(mutant.old, mutant.new), encoding="utf-8")
            try:
                code, seconds = _run_tests(copy, mutant.tests)
            finally:
                target.write_text(original, encoding="utf-8")
            verdict = {0: "survived", 1: "killed", -1: "killed (timeout)"}.get(
                code, f"error (pytest exit {code})"
            )
            print(f"{verdict:10} {seconds:6.1f} s  {mutant.name}", flush=True)
            results.append((mutant, verdict, seconds))
        baseline = sorted({test for mutant in mutants for test in mutant.tests if test.endswith(".py")})
        code, _ = _run_tests(copy, tuple(baseline))
        if code != 0:
            raise SystemExit(f"the unmutated tests fail (pytest exit {code}): the run says nothing")
    return results


def table(results: list[tuple[Mutant, str, float]]) -> str:
    killed = sum(1 for _, verdict, _ in results if verdict.startswith("killed"))
    lines = [
        HEADING,
        "",
        "Measured by `python bench/mutation.py`: each mutant applied alone to a temporary copy of the tree, "
        "the tests that cover it run with `pytest -x` (the slow-marked ones too). "
        f"{len(results)} mutants, {killed} killed, {len(results) - killed} survived.",
        "",
        "| mutant | file | tests | result | seconds |",
        "|---|---|---|---|---|",
    ]
    for mutant, verdict, seconds in results:
        files = ", ".join(Path(test).name for test in mutant.tests if test.endswith(".py"))
        selection = f" (-k {mutant.tests[-1]})" if "-k" in mutant.tests else ""
        lines.append(f"| {mutant.name} | {mutant.path} | {files}{selection} | {verdict} | {seconds:.0f} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--only",
        action="append",
        default=[],
        help="run the mutants whose name contains this text (repeatable)",
    )
    parser.add_argument("--write", action="store_true", help="record the table in bench/RESULTS.md")
    arguments = parser.parse_args()
    chosen = [
        mutant
        for mutant in MUTANTS
        if not arguments.only or any(text in mutant.name for text in arguments.only)
    ]
    results = run(chosen)
    text = table(results)
    print(text)
    if arguments.write:
        replace_section(HEADING, text)


if __name__ == "__main__":
    main()
