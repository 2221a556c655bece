"""A mutation run of the verdict logic: does a green suite prove what it seems to? (issue 34)

Each mutant is one small change to the code that decides a verdict (grader/lab/checks/, and the second
lab's pure checks in grader/lab/rl2/checks/) or to the rules of a compatibility game
(grader/compat/envs/): a statistical decision forced to accept, a comparison flipped, a diagnosis branch
removed, a game rule changed. The checks of random_blackjack, blackjack and taxi have hand-written
mutants; for every other check module (`BRANCH_MODULES`, `RL2_BRANCH_MODULES`) every `if`/`elif` is found
with `ast` and made never to fire (its condition replaced by `False`): each branch that returns a verdict, a
diagnosis or a number the verdict is made of. Every mutant is applied alone to a temporary copy of the
worktree, the tests that cover that code run there (`python -m pytest -x`, slow-marked ones included), and
the mutant is `killed` when they fail, `survived` when they pass. A surviving mutant is a change the tests
cannot see, unless it is listed in `EQUIVALENT` with the reason no test can see it (then `equivalent`).

    python bench/mutation.py                    # every mutant, prints the table
    python bench/mutation.py --only taxi        # the mutants whose name contains "taxi" (--only repeats)
    python bench/mutation.py --write            # and records the table in bench/RESULTS.md
    python bench/mutation.py --list             # the mutants' names, without running them
    python bench/mutation.py --survivors        # again the mutants whose latest logged result is survived
"""

from __future__ import annotations

import argparse
import ast
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.results_section import replace_section

ROOT = Path(__file__).resolve().parents[1]
HEADING = "## Mutation run of the verdict logic (issue 34)"
CHECKS = "grader/lab/checks"
CHECK_TESTS = "tests/grader/lab/checks"
TIMEOUT = 900
RESULTS_LOG = ROOT / "bench" / "mutation_results.jsonl"
"""Every mutant run's result, one JSON object a line, appended as each mutant finishes."""


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


def _files(*names: str, students: str | None = None, leaving_out: str | None = None) -> tuple[str, ...]:
    """The check tests `names` (fastest first: -x stops at the first failure), then the simulated students
    whose test id matches `students` (a -k expression; every test of the other files is kept), without
    the tests matching `leaving_out` (a -k expression: minutes-long trainings that other tests cover)."""
    files = tuple(f"{CHECK_TESTS}/{name}" for name in names)
    if students is not None:
        files += (f"{CHECK_TESTS}/test_students.py",)
    selections = [f"(not test_students or ({students}))"] if students is not None else []
    selections += [f"not ({leaving_out})"] if leaving_out is not None else []
    return (*files, "-k", " and ".join(selections)) if selections else files


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
    # the selection test of the starts (its branches are mutated below too)
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


# The check modules whose every branch is mutated, with the tests that cover each (fastest first).
_LENGTH_STUDENTS = "cartpole or car"
_SARSA_TRAINING = "wrong_epsilon_decay_is_not_counted_again"  # trains sarsa0 for minutes
BRANCH_MODULES: dict[str, tuple[str, ...]] = {
    "cartpole": _files("test_lengths.py", students="cartpole"),
    "car": _files("test_lengths.py", students="car and not cartpole"),
    "guessing_game": _files("test_guessing_game.py"),
    "sarsa": _files("test_sarsa.py", leaving_out=_SARSA_TRAINING),
    "epsilon_decay": _files("test_epsilon_decay.py", "test_sarsa.py", leaving_out=_SARSA_TRAINING),
    "find_qvalues": _files("test_find_qvalues.py"),
    "compare": _files("test_compare.py"),
    "taxi_tables": _files("test_taxi_tables.py"),
    "integrity": _files(
        "test_integrity.py",
        "test_base.py",
        "test_lengths.py",
        "test_guessing_game.py",
        students=_LENGTH_STUDENTS,
    ),
    "lengths": _files(
        "test_lengths.py", "test_guessing_game.py", "test_integrity.py", students=_LENGTH_STUDENTS
    ),
    "truncation": _files("test_taxi.py", students="taxi"),
    "starts": _files("test_starts.py", "test_integrity.py", students="car and not cartpole"),
    "episodes": _files("test_integrity.py", "test_lengths.py"),
    "values": _files("test_values.py", "test_lengths.py", "test_random_blackjack.py", "test_blackjack.py"),
    "sarsa_updates": _files("test_sarsa_updates.py", "test_sarsa.py", leaving_out=_SARSA_TRAINING),
}


RL2_CHECKS = "grader/lab/rl2/checks"
RL2_CHECK_TESTS = "tests/grader/lab/rl2/checks"
RL2_BRANCH_MODULES: dict[str, tuple[str, ...]] = {
    module: tuple(f"{RL2_CHECK_TESTS}/test_{name}.py" for name in names)
    for module, names in {
        "mdp_calls": ("mdp_calls", "value_iteration", "evaluation", "improvement", "policy_iteration"),
        "value_iteration": ("value_iteration", "mdp_calls"),
        "evaluation": ("evaluation", "mdp_calls"),
        "improvement": ("improvement", "mdp_calls"),
        "policy_iteration": ("policy_iteration", "mdp_calls"),
    }.items()
}
"""The second lab's pure checks (their played ones grade through the sandbox: not in this run), with the
tests that cover each; their mutants are named `rl2 <module>: ...`."""


def branch_mutants(
    module: str, tests: tuple[str, ...], checks: str = CHECKS, prefix: str = ""
) -> list[Mutant]:
    """A mutant for every `if`/`elif` of the check module: its condition replaced by `False`.

    Named by module and condition (a repeated condition by its order too). `old` is the branch's header
    (from `if` to the condition's end), widened line by line until it occurs once in the file.
    """
    path = f"{checks}/{module}.py"
    source = (ROOT / path).read_bytes()
    starts = [0]
    for line in source.splitlines(keepends=True):
        starts.append(starts[-1] + len(line))
    mutants: list[Mutant] = []
    seen: dict[str, int] = {}
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, ast.If) or ast.unparse(node.test) == "TYPE_CHECKING":
            continue
        test = node.test
        assert test.end_lineno is not None and test.end_col_offset is not None
        begin = starts[node.lineno - 1]
        condition = (
            starts[test.lineno - 1] + test.col_offset,
            starts[test.end_lineno - 1] + test.end_col_offset,
        )
        end_line = test.end_lineno
        while source.count(source[begin : starts[end_line]]) != 1:
            end_line += 1
        old = source[begin : starts[end_line]]
        new = old[: condition[0] - begin] + b"False" + old[condition[1] - begin :]
        text = " ".join(ast.unparse(test).split())
        shown = text if len(text) <= 70 else text[:67] + "..."
        seen[shown] = seen.get(shown, 0) + 1
        suffix = f" (#{seen[shown]})" if seen[shown] > 1 else ""
        name = f"{prefix}{module}: never `{shown}`{suffix}"
        mutants.append(Mutant(name, path, old.decode(), new.decode(), tests))
    return mutants


MUTANTS += tuple(
    mutant for module, tests in BRANCH_MODULES.items() for mutant in branch_mutants(module, tests)
)
MUTANTS += tuple(
    mutant
    for module, tests in RL2_BRANCH_MODULES.items()
    for mutant in branch_mutants(module, tests, RL2_CHECKS, "rl2 ")
)

EQUIVALENT: dict[str, str] = {
    "taxi: Q beats random dropped": "once the random mean passes its z-test (about -771) and the Q-table "
    "mean its test or floor (above 7), the Q-table mean cannot be at or below the random one; the "
    "condition is redundant, not untested",
    "sarsa: never `any((not episode.reached_terminal for episode in episodes))`": "an episode that is "
    "neither terminated nor truncated already fails `integrity_problem` (abandoned), and one truncated "
    "cannot be recorded: the env's time limit (max_steps + 1) lies beyond the call's step budget "
    "(max_steps), and a call over its budget ends as episode_limit before any episode is judged",
    "lengths: never `not shortfalls or any((shortfall is None for shortfall in shortfalls))`": "a None "
    "shortfall (a count that is no number) returns None below all the same (`first is None`, or "
    "`shortfall != first`); an empty list needs a judgement of no calls, and every length problem plans "
    "`calls` >= 1",
    "starts: never `any((u is None for u in scaled))`": "a rank is None only when a feature of a start "
    "cannot be computed from its replay (a reset that was not replayed); `integrity_problem` refuses such "
    "logs before it runs the selection test, and every reset that reaches the test was replayed from the "
    "grader's seed, so its start and features exist: the branch is a guard, not a decision",
    "values: never `math.isclose(returned, recomputed, rel_tol=1e-09, abs_tol=1e-12)`": "the rounding "
    "loop below ends with round(recomputed, 15), within 5e-16 of the recomputed number, compared by "
    "math.isclose with its default rel_tol (1e-9) and the same abs_tol: the same tolerance, so only a "
    "value within 5e-16 of the tolerance's edge could be judged differently",
    "rl2 mdp_calls: never `len(stopped) == len(set(norms))`": "the early return once every norm has "
    "stopped saves sweeps only: the sweeps after it change no entry of `stopped` (each holds the array of "
    "its own sweep, and every sweep makes a new one), so the same dictionary is returned after maxiter",
}
"""Surviving mutants that no test can kill, with the reason: the mutated code behaves as the original."""


def _copy(destination: Path) -> Path:
    ignored = shutil.ignore_patterns(
        ".git", ".venv", "__pycache__", ".mypy_cache", ".ruff_cache", ".pytest_cache", "node_modules"
    )
    shutil.copytree(ROOT, destination, ignore=ignored)
    return destination


SELECTION = "not sandbox and not e2e and not install and not browser"
"""Every test of the chosen files but those needing the full sandbox or servers: slow-marked ones run too."""


def _run_tests(copy: Path, tests: tuple[str, ...]) -> tuple[int, float]:
    environment = {**os.environ, "PYTHONPATH": str(copy), "PYTHONDONTWRITEBYTECODE": "1"}
    started = time.perf_counter()
    try:
        completed = subprocess.run(
            [
                sys.executable,
                "-m",
                "pytest",
                "-x",
                "-q",
                "-p",
                "no:cacheprovider",
                "-p",
                "no:randomly",
                "-m",
                SELECTION,
                *tests,
            ],
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


def run(mutants: list[Mutant], log: Path) -> list[tuple[Mutant, str, float]]:
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
        for tests in dict.fromkeys(mutant.tests for mutant in mutants):
            code, _ = _run_tests(copy, tests)
            if code != 0:
                raise SystemExit(f"the unmutated tests {' '.join(tests)} fail (pytest exit {code}): no run")
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
            verdict = {
                0: "survived",
                1: "killed",
                2: "killed (collection error)",
                -1: "killed (timeout)",
            }.get(code, f"error (pytest exit {code})")
            if verdict == "survived" and mutant.name in EQUIVALENT:
                verdict = "equivalent"
            print(f"{verdict:10} {seconds:6.1f} s  {mutant.name}", flush=True)
            results.append((mutant, verdict, seconds))
            _record(log, mutant, verdict, seconds)
    return results


def _record(log: Path, mutant: Mutant, verdict: str, seconds: float) -> None:
    with log.open("a", encoding="utf-8") as stream:
        stream.write(
            json.dumps({"name": mutant.name, "result": verdict, "seconds": round(seconds, 1)}) + "\n"
        )


def recorded(log: Path) -> dict[str, tuple[str, float]]:
    """The latest result of each mutant in the log (a mutant renamed or removed since is left out)."""
    names = {mutant.name for mutant in MUTANTS}
    latest: dict[str, tuple[str, float]] = {}
    if log.exists():
        for line in log.read_text(encoding="utf-8").splitlines():
            entry = json.loads(line)
            if entry["name"] in names:
                latest[entry["name"]] = (entry["result"], entry["seconds"])
    return latest


def _module(mutant: Mutant) -> str:
    return Path(mutant.path).name


def table(results: dict[str, tuple[str, float]]) -> str:
    """The RESULTS.md section: totals per module, then every mutant (not yet run: `-`)."""
    rows = [(mutant, *results.get(mutant.name, ("-", 0.0))) for mutant in MUTANTS]
    rows = [  # a survivor listed in EQUIVALENT since its run is reported as such
        (mutant, "equivalent" if verdict == "survived" and mutant.name in EQUIVALENT else verdict, seconds)
        for mutant, verdict, seconds in rows
    ]
    per_module: dict[str, Counter[str]] = {}
    for mutant, verdict, _ in rows:
        kind = verdict.split(" ")[0] if verdict != "-" else "not run"
        per_module.setdefault(_module(mutant), Counter())[kind] += 1
    total: Counter[str] = sum(per_module.values(), Counter())
    lines = [
        HEADING,
        "",
        "Measured by `python bench/mutation.py` (the latest result of each mutant in "
        f"`{RESULTS_LOG.relative_to(ROOT)}`; `--write` rewrites this section from it): each mutant applied "
        "alone to a temporary copy of the tree, the tests that cover it run with `pytest -x` (slow-marked "
        "ones too); the unmutated tests pass in the copy. The checks of random_blackjack, blackjack and taxi "
        "and the toy-text games have hand-written mutants; every other check module, and the second lab's "
        "pure checks (`rl2 ...`: mdp_calls, value_iteration, evaluation, improvement, policy_iteration; its "
        "played checks grade through the sandbox and are not in this run), has one mutant per `if`/`elif` "
        "made never to fire. `equivalent`: the mutant survives and `EQUIVALENT` in the script says why no "
        "test can see it. History: of the 43 hand-written mutants of the first run, 16 survived until their "
        "samples were added (this file's history has that table); of the branch mutants, the survivors of "
        "the first run were given tests (tests/grader/lab/checks/; for the second lab, 8 of 57, "
        "tests/grader/lab/rl2/checks/) and run again with `--survivors`. Seconds are wall times on the "
        "shared two-core machine (load 1 to 13 during the 2026-11-28 runs), not a benchmark.",
        "",
        f"{len(rows)} mutants: {total['killed']} killed, {total['equivalent']} equivalent, "
        f"{total['survived']} survived" + (f", {total['not run']} not run" if total["not run"] else "") + ".",
        "",
        "| module | mutants | killed | equivalent | survived |" + (" not run |" if total["not run"] else ""),
        "|---|---|---|---|---|" + ("---|" if total["not run"] else ""),
    ]
    for module, counts in per_module.items():
        cells = [module, sum(counts.values()), counts["killed"], counts["equivalent"], counts["survived"]]
        if total["not run"]:
            cells.append(counts["not run"])
        lines.append("| " + " | ".join(str(cell) for cell in cells) + " |")
    lines += ["", "| mutant | tests | result | seconds | why it is equivalent |", "|---|---|---|---|---|"]
    for mutant, verdict, seconds in rows:
        files = ", ".join(Path(test).name for test in mutant.tests if test.endswith(".py"))
        selection = f" (-k {mutant.tests[-1]})" if "-k" in mutant.tests else ""
        name = mutant.name.replace("|", "\\|")
        why = EQUIVALENT.get(mutant.name, "") if verdict == "equivalent" else ""
        lines.append(f"| {name} | {files}{selection} | {verdict} | {seconds:.0f} | {why} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--only",
        action="append",
        default=[],
        help="run the mutants whose name contains this text (repeatable)",
    )
    parser.add_argument(
        "--survivors", action="store_true", help="run only the chosen mutants whose logged result is survived"
    )
    parser.add_argument("--list", action="store_true", help="print the chosen mutants' names and stop")
    parser.add_argument(
        "--write", action="store_true", help="record the table of the logged results in bench/RESULTS.md"
    )
    parser.add_argument(
        "--table-only", action="store_true", help="run nothing: the table of the logged results"
    )
    arguments = parser.parse_args()
    chosen = [
        mutant
        for mutant in MUTANTS
        if not arguments.only or any(text in mutant.name for text in arguments.only)
    ]
    if arguments.survivors:
        logged = recorded(RESULTS_LOG)
        chosen = [mutant for mutant in chosen if logged.get(mutant.name, ("",))[0] == "survived"]
    if arguments.list:
        print("\n".join(mutant.name for mutant in chosen))
        return
    if not arguments.table_only:
        run(chosen, RESULTS_LOG)
    text = table(recorded(RESULTS_LOG))
    print(text)
    if arguments.write:
        replace_section(HEADING, text)


if __name__ == "__main__":
    main()
