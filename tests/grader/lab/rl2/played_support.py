"""Run one of the second lab's played checks on a file through the real sandbox, as a grading does.

`grader.grading.execution.run_problem` needs the problem declared in an edition's registry; these helpers
make the same calls (the check's plan, `replay_call`, `settled_by`) with the check's settings bound by hand,
so each check is tested on its own, through the child and the replay, before and after the packs use it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from grader.lab.checks.base import CallRecord, ProblemCheck, Verdict
from grader.lab.checks.integrity import replay_call, settled_by
from grader.lab.games import Game
from grader.lab.settings import ProblemConfig
from grader.sandbox import IsolationPolicy
from grader.sandbox.limits import Limits
from grader.sandbox.runner import Sandbox

ROOT = Path(__file__).resolve().parents[4]
SAMPLES = ROOT / "submissions" / "rl2"

BASE = {"title": "t", "points": 1.0, "call_seconds": 60.0, "expected_seconds": 1.0}


def settings(model: type[ProblemConfig], problem: str, games: tuple[Game, ...], **fields: Any) -> Any:
    """The check's settings with `fields`, bound to `problem` and its games as the loader binds them."""
    return model(**{**BASE, **fields}).for_problem(problem, games)


def records_of(
    submission: Path, check: ProblemCheck[Any], bound: ProblemConfig, *, seed: int = 7
) -> list[CallRecord]:
    """The records of the check's planned calls on `submission` (stopping once the verdict is settled)."""
    records: list[CallRecord] = []
    rules = bound.game_rules()
    limits = Limits(call_seconds=bound.call_seconds)
    with Sandbox(submission, seed=seed, limits=limits, policy=IsolationPolicy.ALLOW_FALLBACK) as sandbox:
        for call in check.plan(bound, sandbox.functions, seed):
            records.append(replay_call(sandbox.call(call), rules))
            if settled_by(records[-1], rules) is not None:
                break
    return records


def verdict_of(submission: Path, check: ProblemCheck[Any], bound: ProblemConfig, *, seed: int = 7) -> Verdict:
    """The check's verdict on `submission`."""
    return check.judge(bound, records_of(submission, check, bound, seed=seed))
