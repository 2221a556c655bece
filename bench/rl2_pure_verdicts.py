"""False-fail and detection rates of the second lab's pure problems on the lab's kind of MDP (issue 43).

Every sample of `submissions/rl2/verdicts.toml` whose entry pins a pure problem (value_iteration, the
improvement and evaluation steps, policy_iteration) is judged by the real check under many problem seeds:
each seed plans the nine public cases and three held-out random MDPs of the lab's shape, with random values
and policies drawn from it. Each planned call is made in this process on the sample's own function (the
table handed over as the sandbox hands it, the value sent through the wire's encoding), and policy_iteration
gets the grader's two readings: the sample's own steps first; where that does not pass, the grader's steps
(`grader.sandbox.child.provided`) bound in the module's namespace, the better verdict kept
(`SecondReading.keep`). A call that runs past `--call-seconds` is a `timeout`, as in the sandbox.

Honest samples must pass every problem at every seed (false-fail = 1 - rate); each mistake sample must get
its pinned status, and its diagnosis where the entry pins one (detection = rate). Everything judged is
exact (no statistic), so a rate below 1 is a seed on which an MDP or a draw hides a mistake or trips an
honest file.

    python -m grader.compat bench/rl2_pure_verdicts.py --seeds 20            # classic gym files need the layer
    python -m grader.compat bench/rl2_pure_verdicts.py --seeds 20 --write    # and replace the section
"""

# ruff: noqa: E501

from __future__ import annotations

import argparse
import dataclasses
import importlib.util
import json
import signal
import sys
import time
import tomllib
from collections.abc import Callable
from pathlib import Path
from types import FrameType, ModuleType
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from grader.lab.assignment import load_config
from grader.lab.checks.base import CallRecord, Verdict
from grader.lab.editions import edition_of
from grader.sandbox.child.frames import MdpArgument, decode_value, encode_value
from grader.sandbox.child.provided import PROVIDED
from grader.sandbox.outcome import CallOutcome, OutcomeStatus

HEADING = (
    "## Second lab: the pure problems' false-fail and detection rates on the lab's kind of MDP (issue 43)"
)
SUBMISSIONS = Path(__file__).resolve().parents[1] / "submissions"
PURE = {
    "value_iteration",
    "extract_policy",
    "policy_improvement",
    "compute_policy_v",
    "iter_policy_eval",
    "policy_iteration",
}


class CallTimeout(Exception):
    """A call ran past its time."""


def _alarm(_signal: int, _frame: FrameType | None) -> None:
    raise CallTimeout


def _module(path: Path) -> ModuleType:
    spec = importlib.util.spec_from_file_location(path.stem, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _outcome(call: Any, function: Callable[..., Any], seconds: float) -> CallOutcome:
    args = [arg.as_table() if isinstance(arg, MdpArgument) else arg for arg in call.args]
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        value = function(*args)
        wired = decode_value(json.loads(json.dumps(encode_value(value, "the value"))), "the value")
        return CallOutcome(call, OutcomeStatus.OK, wired, [], [], "", "", "", 0.0, 0)
    except CallTimeout:
        message = f"{call.function}() did not return within {seconds:g} seconds"
        return CallOutcome(call, OutcomeStatus.TIMEOUT, None, [], [], "", "", message, 0.0, 0)
    except NotImplementedError:
        return CallOutcome(call, OutcomeStatus.EXCEPTION, None, [], [], "", "", "NotImplementedError", 0.0, 0)
    except Exception as error:
        message = f"{type(error).__name__}: {error}"
        return CallOutcome(call, OutcomeStatus.EXCEPTION, None, [], [], "", "", message, 0.0, 0)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)


_MADE: dict[tuple[Any, ...], CallOutcome] = {}
"""Outcomes of calls already made, by module, function, arguments and names bound: the public cases are
asked alike under every seed, and every sample's functions are deterministic (none draws its start)."""


def _key(module: ModuleType, call: Any) -> tuple[Any, ...]:
    args = tuple(
        ("mdp", arg.table)
        if isinstance(arg, MdpArgument)
        else ("array", arg.tobytes(), str(arg.dtype))
        if isinstance(arg, np.ndarray)
        else arg
        for arg in call.args
    )
    return (module.__name__, call.function, args, call.provided)


def _reading(check: Any, chosen: Any, calls: list[Any], module: ModuleType, seconds: float) -> Verdict:
    """One reading's calls made in order (stopping at the first that does not return), then judged."""
    records = []
    for call in calls:
        function = getattr(module, call.function, None)
        key = _key(module, call)
        if function is None:
            message = f"no {call.function}"
            outcome = CallOutcome(call, OutcomeStatus.MISSING_FUNCTION, None, [], [], "", "", message, 0.0, 0)
        elif key in _MADE:
            outcome = dataclasses.replace(_MADE[key], call=call)
        else:
            kept = {name: vars(module).get(name) for name in call.provided}
            vars(module).update({name: PROVIDED[name] for name in call.provided})
            try:
                outcome = _outcome(call, function, seconds)
            finally:
                vars(module).update(kept)
            _MADE[key] = outcome
        records.append(CallRecord(outcome, []))
        if outcome.status is not OutcomeStatus.OK:
            break
    return check.judge(chosen, records)


def verdict(edition: str, problem: str, module: ModuleType, seed: int, seconds: float) -> Verdict:
    """The check's verdict on the module's function under one problem seed, both readings where it has two."""
    pack = edition_of(edition)
    entry = pack.registry.problem(problem)
    chosen = entry.settings(load_config(pack.default_config))
    check = entry.check
    first = _reading(check, chosen, check.plan(chosen, {}, seed), module, seconds)
    if hasattr(check, "second_plan"):
        again = check.second_plan(chosen, first, {}, seed)
        if again:
            return check.keep(chosen, first, _reading(check, chosen, again, module, seconds))
    return first


def main() -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--first-seed", type=int, default=43_000)
    parser.add_argument("--call-seconds", type=float, default=60.0)
    parser.add_argument("--write", action="store_true")
    args = parser.parse_args()
    signal.signal(signal.SIGALRM, _alarm)
    started = time.perf_counter()
    entries = tomllib.loads((SUBMISSIONS / "rl2" / "verdicts.toml").read_text(encoding="utf-8"))["sample"]
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    rows = []
    for entry in entries:
        pinned = {p: s for p, s in entry["status"].items() if p in PURE}
        if not pinned or entry["file"].startswith("rl2/templates/"):
            continue
        module = _module(SUBMISSIONS / entry["file"])
        for problem, status in pinned.items():
            words = entry.get("feedback", {}).get(problem, "")
            matched = 0
            seen: dict[str, int] = {}
            for seed in seeds:
                got = verdict(entry["edition"], problem, module, seed, args.call_seconds)
                seen[got.status] = seen.get(got.status, 0) + 1
                matched += got.status == status and (not words or words in got.feedback)
            kind = "honest: false-fail = 1 - rate" if status == "passed" else "detection"
            statuses = ", ".join(f"{name} {count}" for name, count in sorted(seen.items()))
            rows.append(
                f"| {entry['file'].removeprefix('rl2/')} ({entry['edition']}) | {problem} | {status}"
                f"{f' (names {words!r})' if words else ''} | {kind} | {matched}/{len(seeds)} | {statuses} |"
            )
            print(rows[-1], flush=True)
    took = time.perf_counter() - started
    honest = [row for row in rows if "| honest:" in row]
    caught = [row for row in rows if "| detection |" in row]
    full = f"| {len(seeds)}/{len(seeds)} |"
    summary = (
        f"Reading: {sum(full in row for row in honest)} of {len(honest)} honest rows passed at every seed (false-fail "
        f"0 of {len(honest) * len(seeds)} verdicts); {sum(full in row for row in caught)} of {len(caught)} mistake "
        "rows got their pinned status (and named diagnosis) at every seed."
    )
    text = "\n".join(
        [
            HEADING,
            "",
            f"`python -m grader.compat bench/rl2_pure_verdicts.py --seeds {args.seeds}` (problem seeds {seeds.start} to {seeds.stop - 1}): every",
            "sample of `submissions/rl2/verdicts.toml` that pins a pure problem, judged by the real check under each",
            "seed (the nine public MDPs of the lab's kind and three held-out random MDPs of its shape, with the",
            "seed's random values and policies), the calls made in-process on the sample's own functions;",
            "policy_iteration with both readings (the sample's own steps, then, where that does not pass, the",
            f"grader's), a call past {args.call_seconds:g} s a `timeout`. Everything judged is exact: a rate below 1 would be",
            "a seed whose MDPs or draws hide a mistake or trip an honest file.",
            "",
            "| sample | problem | pinned status | row | rate | statuses seen |",
            "|---|---|---|---|---|---|",
            *rows,
            "",
            summary,
            "",
            f"Took {took:.0f} s.",
            "",
            "",
        ]
    )
    print(f"took {took:.0f} s")
    if args.write:
        from bench.results_section import replace_section

        replace_section(HEADING, text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
