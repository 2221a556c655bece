"""A fast stand-in for grader.grading.grade.grade_submission whose behaviour the uploaded file itself chooses.

Directives in the file (one per line):
    ``# fake-grader: sleep=SECONDS``  wait this long before each problem finishes (a cost, never a window
                                      a test's verdict depends on: for that, ``hold``);
    ``# fake-grader: hold=PATH``      wait until the file PATH exists, before the first problem or the one
                                      ``# fake-grader: hold-before=PROBLEM_ID`` names: the test sees the
                                      grading under way, acts, then makes PATH (`held`, `release`);
    ``# fake-grader: crash``          kill the grading process (as a crash would);
    ``# fake-grader: fail``           raise, as a broken grader would;
    ``# fake-grader: internal-error`` return a report that lists a failure of the grader itself.
A problem passes when the file defines its function, and is missing otherwise; a file that does not
compile gets a ``submission_error``, as the real grader's validation gives.
"""

from __future__ import annotations

import hashlib
import os
import re
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from pydantic import JsonValue

import grader
from grader.grading.plan import GradingPlan
from grader.report import ProblemResult, Report

PROBLEMS = (
    ("random_blackjack", "Random blackjack"),
    ("blackjack", "Threshold blackjack"),
    ("cartpole", "CartPole"),
)
POINTS = 1.0
BLACKJACK_MEASUREMENTS: dict[str, JsonValue] = {
    "exact_curve": {str(n): 0.38 + 0.003 * min(n, 13) - 0.02 * max(n - 13, 0) for n in range(22)},
    "curve": {"12": 0.41, "13": 0.42, "14": 0.41, "20": 0.25},
}
"""Shaped as the real blackjack check writes them, so the real plotter draws them."""


def _directive(source: str, name: str) -> str | None:
    match = re.search(rf"^# fake-grader: {name}(?:=(\S+))?\s*$", source, flags=re.MULTILINE)
    if match is None:
        return None
    return match.group(1) or ""


HOLD_SECONDS = 300.0
"""Bounds a hold that is never released (a broken test): the grading then fails, saying so."""


def held(path: Path, before: str | None = None) -> bytes:
    """The directives that hold a grading until :func:`release` (``path``: a file that does not exist yet),
    before its first problem or the problem ``before``."""
    return f"# fake-grader: hold={path}\n".encode() + (
        f"# fake-grader: hold-before={before}\n".encode() if before else b""
    )


def release(path: Path) -> None:
    """Let every grading held on ``path`` go on."""
    path.touch()


def _hold(path: Path) -> None:
    deadline = time.monotonic() + HOLD_SECONDS
    while not path.exists():
        if time.monotonic() > deadline:
            raise RuntimeError(f"the fake grader was held on {path} and not released within {HOLD_SECONDS} s")
        time.sleep(0.02)


def grade_submission(
    path: Path,
    *,
    seed: int = 0,
    workers: int | None = None,
    only: Sequence[str] | None = None,
    policy: Any = None,
    on_progress: Callable[[ProblemResult], None] | None = None,
    config: Path | None = None,
    name: str | None = None,
) -> Report:
    """Grade ``path`` the fake way (see the module docstring); ``only`` picks among its problems.

    Reports carry the real configuration digest of ``config``, so a resumed batch can reuse them, and name
    the file ``name`` (its own name as shown, the real grader's parameter), ``path.name`` when None.
    """
    shown = name or path.name
    data = path.read_bytes()
    source = data.decode("utf-8")
    sha256 = hashlib.sha256(data).hexdigest()
    chosen = [(problem_id, title) for problem_id, title in PROBLEMS if only is None or problem_id in only]
    config_sha256 = GradingPlan.load(config, only).config_sha256 if only is not None else ""
    if _directive(source, "crash") is not None:
        os._exit(3)
    if _directive(source, "fail") is not None:
        raise RuntimeError("the fake grader was told to fail")
    try:
        compile(source, path.name, "exec")
    except SyntaxError as error:
        message = f"{shown} is not valid Python: line {error.lineno}: {error.msg}"
        return Report(
            submission=shown,
            sha256=sha256,
            seed=seed,
            config_sha256=config_sha256,
            gymnasium_version="fake",
            grader_version=grader.__version__,
            score=0.0,
            max_score=POINTS * len(chosen),
            submission_error=message,
            problems=[
                ProblemResult(
                    id=problem_id, title=title, status="error", score=0.0, max_score=POINTS, feedback=message
                )
                for problem_id, title in chosen
            ],
        )
    hold = _directive(source, "hold")
    hold_before = _directive(source, "hold-before") or (chosen[0][0] if chosen else None)
    delay = float(_directive(source, "sleep") or 0.0)
    problems = []
    for problem_id, title in chosen:
        if hold and problem_id == hold_before:
            _hold(Path(hold))
        time.sleep(delay)
        defined = re.search(rf"^def {problem_id}\(", source, flags=re.MULTILINE) is not None
        result = ProblemResult(
            id=problem_id,
            title=title,
            status="passed" if defined else "missing",
            score=POINTS if defined else 0.0,
            max_score=POINTS,
            feedback=f"{problem_id} is defined."
            if defined
            else f"expected a function {problem_id}; found none",
            measurements=BLACKJACK_MEASUREMENTS
            if problem_id == "blackjack"
            else {"policy": str(policy), "workers": workers},
            output=f"<output of {problem_id}>",
            seed=seed,
        )
        problems.append(result)
        if on_progress is not None:
            on_progress(result)
    return Report(
        submission=shown,
        sha256=sha256,
        seed=seed,
        config_sha256=config_sha256,
        gymnasium_version="fake",
        grader_version=grader.__version__,
        score=sum(p.score for p in problems),
        max_score=POINTS * len(problems),
        problems=problems,
        grader_errors=["cartpole: the fake grader crashed"]
        if _directive(source, "internal-error") is not None
        else [],
    )


def grade_as_configured(
    path: Path,
    *,
    seed: int = 0,
    workers: int | None = None,
    only: Sequence[str] | None = None,
    policy: Any = None,
    on_progress: Callable[[ProblemResult], None] | None = None,
    config: Path | None = None,
    name: str | None = None,
) -> Report:
    """A grader that grades nothing but reports the configuration it was given: every enabled problem of
    ``config`` (the bundled one when None) passed with its configured points and visibility, and the
    configuration's edition as each problem's ``measurements["edition"]``."""
    plan = GradingPlan.load(config, only)
    data = path.read_bytes()
    problems = []
    for problem_id in plan.problems:
        result = ProblemResult(
            id=problem_id,
            title=plan.titles[problem_id],
            status="passed",
            score=plan.points[problem_id],
            max_score=plan.points[problem_id],
            feedback="as configured",
            measurements={"edition": plan.edition},
            visibility=plan.visibility[problem_id],
            seed=seed,
        )
        problems.append(result)
        if on_progress is not None:
            on_progress(result)
    return Report(
        submission=name or path.name,
        sha256=hashlib.sha256(data).hexdigest(),
        seed=seed,
        config_sha256=plan.config_sha256,
        gymnasium_version="fake",
        grader_version=grader.__version__,
        score=sum(p.score for p in problems),
        max_score=sum(p.max_score for p in problems),
        problems=problems,
    )
