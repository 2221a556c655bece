"""sarsa0 through the real sandbox: the grader's env and, when configured, the grader's own epsilon_decay."""

from __future__ import annotations

import json
import textwrap
import tomllib
from pathlib import Path

import pytest

from grader.grading.grade import grade_files
from grader.grading.plan import GradingPlan
from grader.lab.editions.rl1 import RL1
from grader.report import ProblemResult
from grader.sandbox import IsolationPolicy

pytestmark = pytest.mark.slow  # grades through the sandbox

REFERENCE = Path(RL1.reference).read_text(encoding="utf-8")
BROKEN_DECAY = textwrap.dedent("""
    def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
        raise NotImplementedError("Problem 5 incomplete")
""")


def _grade(tmp_path: Path, source: str, schedule: str) -> ProblemResult:
    submission = tmp_path / "gymnasium.py"
    submission.write_text(source, encoding="utf-8")
    config = tomllib.loads(RL1.default_config.read_text(encoding="utf-8"))
    config["problems"]["sarsa0"].update(episodes=10, decay_episodes=5, decay_schedule=schedule)
    lines = ['edition = "rl1"']
    for table, fields in [
        *(("problems." + name, f) for name, f in config["problems"].items()),
        ("sandbox", config["sandbox"]),
    ]:
        lines.append(f"[{table}]")
        lines += [f"{name} = {json.dumps(value)}" for name, value in fields.items()]
    path = tmp_path / "rl1.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    plan = GradingPlan.load(path, ("sarsa0",))
    (report,) = grade_files([submission], plan, seed=7, workers=1, policy=IsolationPolicy.ALLOW_FALLBACK)
    (result,) = report.problems
    return result


@pytest.mark.parametrize("schedule", ["student", "grader"])
def test_the_reference_passes_with_either_schedule(tmp_path: Path, schedule: str) -> None:
    result = _grade(tmp_path, REFERENCE, schedule)
    assert result.status == "passed", result.feedback
    assert "the decay=True call (N=5)" in result.feedback


def test_the_graders_epsilon_decay_stands_in_for_a_broken_one(tmp_path: Path) -> None:
    """With decay_schedule = "grader" a broken epsilon_decay is counted in problem 5 only."""
    result = _grade(tmp_path, REFERENCE + BROKEN_DECAY, "grader")
    assert result.status == "passed", result.feedback


def test_with_the_students_schedule_a_broken_epsilon_decay_skips_the_decay_call(tmp_path: Path) -> None:
    result = _grade(tmp_path, REFERENCE + BROKEN_DECAY, "student")
    assert result.status == "passed", result.feedback
    assert "The decay=True call was not made" in result.feedback
