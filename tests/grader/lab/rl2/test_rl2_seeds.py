"""The second lab graded under several grading seeds: every honest file and every edition's reference
solution passes each pure problem whatever the held-out MDPs drawn, and the same bytes and seed give the
same report (the MDPs and draws of a problem derive from its seed, `grader.lab.rl2.checks.mdp_calls`)."""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest

from grader.grading.grade import grade_files
from grader.grading.plan import GradingPlan
from grader.lab.editions import edition_of
from grader.lab.rl2.editions import PURE_2018, PURE_2023, PURE_2024
from grader.report import Report
from grader.sandbox import IsolationPolicy
from reference.rl2.editions import EDITIONS
from tests.grader.lab.rl2.support import judged

SUBMISSIONS = Path(__file__).resolve().parents[4] / "submissions" / "rl2"
PURE = frozenset(problem.id for problem in (*PURE_2018, *PURE_2023, *PURE_2024))
"""The problems judged in this process: the played ones (run_simulation, frozen_lake, model_comparison) play
episodes that only the sandbox records and replays (and 2019's render in a window), so they are graded
through the sandbox below."""
SEEDS = (1, 2, 3, 4, 5)
"""Grading seeds (each draws three held-out MDPs and the random inputs of every case)."""
HONEST = {
    "v2018": ("honest_v2018.py",),
    "v2019": ("honest_v2019.py",),
    "v2023": ("honest_v2023.py",),
    "v2024": ("honest_v2024.py",),
    "v2026": ("policy_function_iteration.py", "honest_value_iteration_in_place.py"),
}


def _verdicts(report: Report) -> list[tuple[str, str, float, str, object, int]]:
    """Everything of a report that the seed decides (not its timings)."""
    return [(p.id, p.status, p.score, p.feedback, p.measurements, p.seed) for p in report.problems]


@pytest.mark.slow  # 5 seeds x 5 editions x 4 problems judged in this process (about two minutes)
@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("edition", EDITIONS)
def test_each_editions_reference_passes_under_the_seed(edition: str, seed: int) -> None:
    solution = importlib.import_module(f"reference.rl2.editions.{edition}")
    for problem in [id for id in edition_of(edition).registry.ids if id in PURE]:
        verdict = judged(edition, problem, getattr(solution, problem), seed=seed)
        assert verdict.status == "passed", (problem, verdict.feedback)


@pytest.mark.slow  # 5 seeds x 6 files graded through the sandbox (several minutes on two cores)
@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("edition", sorted(HONEST))
def test_every_honest_file_passes_under_the_seed(edition: str, seed: int) -> None:
    plan = GradingPlan.load(edition_of(edition).default_config, edition_of(edition).registry.ids)
    paths = [SUBMISSIONS / name for name in HONEST[edition]]
    for report in grade_files(paths, plan, seed=seed, workers=2, policy=IsolationPolicy.ALLOW_FALLBACK):
        assert report.grader_errors == []
        assert {p.id: p.status for p in report.problems} == dict.fromkeys(plan.problems, "passed"), [
            p.feedback for p in report.problems
        ]


@pytest.mark.slow  # two gradings of two files through the sandbox
def test_the_same_seed_gives_the_same_report_and_another_seed_other_mdps() -> None:
    edition = edition_of("v2024")
    plan = GradingPlan.load(edition.default_config, edition.registry.ids)
    paths = [SUBMISSIONS / "hostile" / "memorised_public_cases.py", SUBMISSIONS / "honest_v2024.py"]
    first, again, other = (
        grade_files(paths, plan, seed=seed, workers=2, policy=IsolationPolicy.ALLOW_FALLBACK)
        for seed in (7, 7, 8)
    )
    assert [_verdicts(r) for r in first] == [_verdicts(r) for r in again]
    # the memoriser's feedback names the first held-out MDP it fails on, with that MDP's values
    assert [p.feedback for p in first[0].problems] != [p.feedback for p in other[0].problems]
