"""Every sample submission gets the per-problem statuses (and diagnoses) `submissions/verdicts.toml` pins.

Each sample is graded through the real sandbox only on the problems its entry lists. Samples listing the
same problems share one grading run (longest checks first on two workers); the runs themselves overlap,
so one run's idle tail is filled by another's work. The configuration is the bundled one with fewer
games where no verdict depends on the number (see SAMPLE_OVERRIDES).
"""

from __future__ import annotations

import tomllib
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest
from grading_support import SUBMISSIONS, write_config

from grader.grading.grade import grade_files
from grader.grading.plan import GradingPlan
from grader.lab.assignment import load_config
from grader.lab.problems import PROBLEM_IDS, ProblemId
from grader.report import Report
from grader.sandbox import IsolationPolicy

pytestmark = [
    pytest.mark.slow,  # grades every sample submission through the real sandbox
    pytest.mark.xdist_group("samples"),  # one worker grades `reports` for all samples
]

VERDICTS = SUBMISSIONS / "verdicts.toml"
HONEST_VERDICTS = SUBMISSIONS / "honest" / "verdicts.toml"
HOSTILE_OUTCOMES = SUBMISSIONS / "hostile" / "outcomes.toml"
SEED = 20261122
CONCURRENT_RUNS = 3

SAMPLE_OVERRIDES: dict[str, dict[str, Any]] = {
    # The random-play samples differ from random play at any n (average reward instead of wins, a player
    # that never draws); 2000 games keep each exact test's false-fail probability at the configured 1e-6.
    "random_blackjack": {"games": 2000},
    # n = 12 shows both blackjack mistakes in the replayed decisions (standing on exactly 12; a first
    # decision taken on the previous game's hand); the complete solutions pass at any n.
    "blackjack": {"thresholds": [12]},
    # Honest car() calls take milliseconds; a shorter limit keeps the endless sample's timeout cheap.
    "car": {"call_seconds": 5.0},
    # The optional problem is off in the bundled file; its samples are graded with it on.
    "guessing_game": {"enabled": True},
    # Worth 0 points, find_qvalues is not called by default (status "skipped"); the samples' tables are
    # checked all the same.
    "find_qvalues": {"run": "always"},
}


@dataclass(frozen=True)
class Sample:
    """One entry of verdicts.toml."""

    file: str
    status: dict[str, str]
    feedback: dict[str, str] = field(default_factory=dict)

    @property
    def path(self) -> Path:
        return SUBMISSIONS / self.file

    @property
    def problems(self) -> tuple[ProblemId, ...]:
        return tuple(problem for problem in PROBLEM_IDS if problem in self.status)


def _samples() -> list[Sample]:
    entries = tomllib.loads(VERDICTS.read_text(encoding="utf-8"))["sample"]
    entries += tomllib.loads(HONEST_VERDICTS.read_text(encoding="utf-8"))["sample"]
    entries += tomllib.loads(HOSTILE_OUTCOMES.read_text(encoding="utf-8"))["verdict"]
    return [Sample(entry["file"], entry["status"], entry.get("feedback", {})) for entry in entries]


SAMPLES = _samples()


@pytest.fixture(scope="module")
def reports(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Report]:
    """Every sample's report, keyed by its file."""
    config = write_config(tmp_path_factory.mktemp("config") / "assignment.toml", SAMPLE_OVERRIDES)
    groups: dict[tuple[ProblemId, ...], list[Sample]] = {}
    for sample in SAMPLES:
        groups.setdefault(sample.problems, []).append(sample)

    def grade(problems: tuple[ProblemId, ...]) -> list[Report]:
        paths = [sample.path for sample in groups[problems]]
        plan = GradingPlan.load(config, problems)
        return grade_files(paths, plan, seed=SEED, workers=2, policy=IsolationPolicy.ALLOW_FALLBACK)

    assignment = load_config(config)

    def expected_seconds(problems: tuple[ProblemId, ...]) -> float:
        per_sample = sum(assignment.problem(problem).expected_seconds for problem in problems)
        return per_sample * len(groups[problems])

    # Longest runs first, so the short ones fill the gaps at the end.
    order = sorted(groups, key=expected_seconds, reverse=True)
    with ThreadPoolExecutor(max_workers=CONCURRENT_RUNS) as pool:
        graded = dict(zip(order, pool.map(grade, order), strict=True))
    return {
        sample.file: report
        for problems in order
        for sample, report in zip(groups[problems], graded[problems], strict=True)
    }


@pytest.mark.parametrize("sample", SAMPLES, ids=[sample.file for sample in SAMPLES])
def test_sample_gets_its_verdicts(sample: Sample, reports: dict[str, Report]) -> None:
    report = reports[sample.file]
    assert report.grader_errors == []
    feedback = {problem.id: problem.feedback for problem in report.problems}
    found = {problem.id: problem.status for problem in report.problems}
    assert found == sample.status, feedback
    for problem, text in sample.feedback.items():
        assert text in feedback[problem], feedback[problem]
