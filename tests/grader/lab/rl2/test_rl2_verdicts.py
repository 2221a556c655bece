"""Every sample of the second lab gets, from the grader, the statuses (and diagnoses) that
`submissions/rl2/verdicts.toml` pins for the problems the grader grades today (the pure problems).

Graded through the real sandbox with its edition's default configuration, only on the graded problems its
entry lists; samples of one edition listing the same problems share one grading run.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from grader.grading.grade import grade_files
from grader.grading.plan import GradingPlan
from grader.lab.editions import edition_of
from grader.lab.registry import ProblemId
from grader.report import Report
from grader.sandbox import IsolationPolicy

SUBMISSIONS = Path(__file__).resolve().parents[4] / "submissions"
VERDICTS = SUBMISSIONS / "rl2" / "verdicts.toml"
SEED = 20261128


@dataclass(frozen=True)
class Sample:
    """One entry of the verdicts file, restricted to the problems its edition's registry grades."""

    file: str
    edition: str
    status: dict[str, str]
    feedback: dict[str, str] = field(default_factory=dict)

    @property
    def problems(self) -> tuple[ProblemId, ...]:
        return tuple(problem for problem in edition_of(self.edition).registry.ids if problem in self.status)


def _sample(entry: dict[str, object]) -> Sample:
    edition = str(entry["edition"])
    graded = set(edition_of(edition).registry.ids)
    status = {p: s for p, s in entry["status"].items() if p in graded}  # type: ignore[attr-defined]
    feedback = {p: t for p, t in entry.get("feedback", {}).items() if p in graded}  # type: ignore[attr-defined]
    return Sample(str(entry["file"]), edition, status, feedback)


ENTRIES = tomllib.loads(VERDICTS.read_text(encoding="utf-8"))["sample"]
SAMPLES = [sample for sample in map(_sample, ENTRIES) if sample.status]


def test_every_entry_names_the_lab_and_an_edition_of_it() -> None:
    assert {entry["lab"] for entry in ENTRIES} == {"rl2"}
    assert all(edition_of(entry["edition"]).lab == "rl2" for entry in ENTRIES)


def test_every_typical_mistake_of_the_pure_problems_is_pinned_with_its_diagnosis() -> None:
    failing = [s for s in SAMPLES if "failed" in s.status.values() or "timeout" in s.status.values()]
    assert len(failing) >= 8
    for sample in failing:
        if sample.file != "rl2/mistakes/hard_coded_example.py":
            assert sample.feedback, sample.file


@pytest.fixture(scope="module")
def reports() -> dict[str, Report]:
    """Every sample's report, keyed by its file."""
    groups: dict[tuple[str, tuple[ProblemId, ...]], list[Sample]] = {}
    for sample in SAMPLES:
        groups.setdefault((sample.edition, sample.problems), []).append(sample)
    found: dict[str, Report] = {}
    for (edition, problems), samples in groups.items():
        plan = GradingPlan.load(edition_of(edition).default_config, problems)
        paths = [SUBMISSIONS / sample.file for sample in samples]
        graded = grade_files(paths, plan, seed=SEED, workers=2, policy=IsolationPolicy.ALLOW_FALLBACK)
        found.update({sample.file: report for sample, report in zip(samples, graded, strict=True)})
    return found


@pytest.mark.xdist_group("rl2-samples")  # one worker grades `reports` for all samples
@pytest.mark.slow  # grades every sample through the sandbox (about a minute on two cores)
@pytest.mark.parametrize("sample", SAMPLES, ids=[sample.file for sample in SAMPLES])
def test_sample_gets_its_verdicts(sample: Sample, reports: dict[str, Report]) -> None:
    report = reports[sample.file]
    assert report.grader_errors == []
    assert report.edition == sample.edition
    feedback = {problem.id: problem.feedback for problem in report.problems}
    assert {problem.id: problem.status for problem in report.problems} == sample.status, feedback
    for problem, text in sample.feedback.items():
        assert text in feedback[problem], feedback[problem]
