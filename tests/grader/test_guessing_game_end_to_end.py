"""The optional guessing_game problem end to end: off by default, graded through the real sandbox when on."""

from __future__ import annotations

from pathlib import Path

import pytest
from grading_support import SUBMISSIONS, write_config

from grader.grading.grade import grade_submission
from grader.grading.plan import GradingPlan
from grader.sandbox import IsolationPolicy

pytestmark = pytest.mark.slow  # grades through the real sandbox

HONEST = SUBMISSIONS / "guessing_game.py"


@pytest.fixture(scope="module")
def enabled_config(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("config") / "assignment.toml"
    return write_config(path, {"guessing_game": {"enabled": True, "calls": 30}})


def test_the_bundled_configuration_does_not_grade_it() -> None:
    assert "guessing_game" not in GradingPlan.load(None, None).problems
    assert GradingPlan.load(None, ["guessing_game"]).problems == ()


@pytest.mark.parametrize(
    ("sample", "status", "feedback"),
    [
        (HONEST, "passed", "your 30 replayed games took"),
        (SUBMISSIONS / "mistakes" / "guessing_game_uncounted_win.py", "failed", "off by one"),
    ],
    ids=["midpoint", "uncounted-win"],
)
def test_a_configuration_that_enables_it_grades_it(
    enabled_config: Path, sample: Path, status: str, feedback: str
) -> None:
    report = grade_submission(
        sample,
        seed=11,
        workers=1,
        only=["guessing_game"],
        policy=IsolationPolicy.ALLOW_FALLBACK,
        config=enabled_config,
    )
    assert report.grader_errors == []
    [result] = report.problems
    assert (result.id, result.status, result.title) == ("guessing_game", status, "Optional: GuessingGame")
    assert feedback in result.feedback
    assert result.measurements["calls"] == 30
