"""Every later-edition sample gets the statuses (and diagnoses) `submissions/editions/verdicts.toml` pins.

Graded through the real sandbox with its edition's pack (the default configuration, with fewer games where
no verdict depends on the number), only on the problems its entry lists; samples listing the same problems
share one grading run.
"""

from __future__ import annotations

import json
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from grader.grading.grade import grade_files
from grader.grading.plan import GradingPlan
from grader.lab.editions import edition_of
from grader.lab.registry import ProblemId
from grader.report import Report
from grader.sandbox import IsolationPolicy

SUBMISSIONS = Path(__file__).resolve().parents[4] / "submissions"
VERDICTS = SUBMISSIONS / "editions" / "verdicts.toml"
SEED = 20261125
OVERRIDES: dict[str, dict[str, Any]] = {
    "random_blackjack": {"games": 2000},
    "blackjack": {"thresholds": [12]},
    "cartpole": {"calls": 20},
    "car": {"calls": 20},
    # A loaded test machine gets twice the default limit for the cells, which changes no verdict.
    "compare": {"cells_seconds": 3600.0},
}
LAB_EPISODES = "N=70_000"
"""The learners' default in the course's template: samples with `suite_episodes` are graded here from a copy
whose learners default to that many episodes instead (compare() is judged on the tables played, whatever
they learned; the lab-sized grading of the same files is `bench/compare_cost.py`'s, minutes each)."""


@dataclass(frozen=True)
class Sample:
    """One entry of the verdicts file."""

    file: str
    edition: str
    status: dict[str, str]
    feedback: dict[str, str] = field(default_factory=dict)
    suite_episodes: int | None = None

    @property
    def problems(self) -> tuple[ProblemId, ...]:
        return tuple(problem for problem in edition_of(self.edition).registry.ids if problem in self.status)


SAMPLES = [
    Sample(
        entry["file"],
        entry["edition"],
        entry["status"],
        entry.get("feedback", {}),
        entry.get("suite_episodes"),
    )
    for entry in tomllib.loads(VERDICTS.read_text(encoding="utf-8"))["sample"]
]


def _toml(config: dict[str, Any]) -> str:
    lines = [f"edition = {json.dumps(config['edition'])}"]
    for table, fields in [
        *(("problems." + name, f) for name, f in config["problems"].items()),
        ("sandbox", config["sandbox"]),
    ]:
        lines.append(f"[{table}]")
        lines += [f"{name} = {json.dumps(value)}" for name, value in fields.items()]
    return "\n".join(lines) + "\n"


def _config(directory: Path, edition: str) -> Path:
    config = tomllib.loads(edition_of(edition).default_config.read_text(encoding="utf-8"))
    config["edition"] = edition  # the bundled configuration names none: editions 1-3 grade its problems
    for problem, fields in OVERRIDES.items():
        if problem in config["problems"]:
            config["problems"][problem].update(fields)
    path = directory / f"{edition}.toml"
    path.write_text(_toml(config), encoding="utf-8")
    return path


def _graded_copy(sample: Sample, directory: Path) -> Path:
    """The file graded for a sample: the sample itself, or a copy whose learners train fewer episodes."""
    path = SUBMISSIONS / sample.file
    if sample.suite_episodes is None:
        return path
    text = path.read_text(encoding="utf-8")
    assert text.count(LAB_EPISODES) == 2, "qlearn and sarsa0 default to the lab's episodes"
    copy = directory / sample.file
    copy.parent.mkdir(parents=True, exist_ok=True)
    copy.write_text(text.replace(LAB_EPISODES, f"N={sample.suite_episodes}"), encoding="utf-8")
    return copy


@pytest.fixture(scope="module")
def reports(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Report]:
    """Every sample's report, keyed by its file."""
    directory = tmp_path_factory.mktemp("config")
    groups: dict[tuple[str, tuple[ProblemId, ...]], list[Sample]] = {}
    for sample in SAMPLES:
        groups.setdefault((sample.edition, sample.problems), []).append(sample)
    found: dict[str, Report] = {}
    for (edition, problems), samples in groups.items():
        plan = GradingPlan.load(_config(directory, edition), problems)
        paths = [_graded_copy(sample, directory) for sample in samples]
        graded = grade_files(paths, plan, seed=SEED, workers=2, policy=IsolationPolicy.ALLOW_FALLBACK)
        found.update({sample.file: report for sample, report in zip(samples, graded, strict=True)})
    return found


def test_at_least_five_epsilon_decay_mistakes_are_pinned() -> None:
    failing = [sample for sample in SAMPLES if sample.status.get("epsilon_decay") == "failed"]
    assert len(failing) >= 5
    assert all(sample.feedback.get("epsilon_decay") for sample in failing)


def test_at_least_five_sarsa0_mistakes_are_pinned() -> None:
    failing = [sample for sample in SAMPLES if sample.status.get("sarsa0") == "failed"]
    assert len(failing) >= 5
    assert all(sample.feedback.get("sarsa0") for sample in failing)


@pytest.mark.xdist_group("edition-samples")  # one worker grades `reports` for all samples
@pytest.mark.slow  # grades every edition's samples through the sandbox
@pytest.mark.parametrize("sample", SAMPLES, ids=[sample.file for sample in SAMPLES])
def test_sample_gets_its_verdicts(sample: Sample, reports: dict[str, Report]) -> None:
    report = reports[sample.file]
    assert report.grader_errors == []
    feedback = {problem.id: problem.feedback for problem in report.problems}
    assert {problem.id: problem.status for problem in report.problems} == sample.status, feedback
    for problem, text in sample.feedback.items():
        assert text in feedback[problem], feedback[problem]
