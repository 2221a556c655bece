"""The second lab's samples (submissions/rl2/verdicts.toml) get their pinned statuses from the oracles.

Each sample runs in a child through `python -m grader.compat` (classic `gym` for the old editions), judged
by sample_judge.py on every MDP and discount of `reference.oracles.mdps.grading_cases(seed)` (the public
cases and one seed's held-out random MDPs). Only the pure
problems and run_simulation are judged here; frozen_lake and model_comparison need the grader's lab.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
VERDICTS = ROOT / "submissions" / "rl2" / "verdicts.toml"
JUDGE = Path(__file__).with_name("sample_judge.py")
JUDGED = {
    "value_iteration",
    "extract_policy",
    "policy_improvement",
    "compute_policy_v",
    "iter_policy_eval",
    "policy_iteration",
    "run_simulation",
}
SAMPLES = tomllib.loads(VERDICTS.read_text(encoding="utf-8"))["sample"]


def test_every_sample_file_exists_and_every_file_is_pinned() -> None:
    pinned = {sample["file"] for sample in SAMPLES}
    on_disk = {
        str(path.relative_to(ROOT / "submissions")) for path in (ROOT / "submissions" / "rl2").rglob("*.py")
    }
    assert pinned == on_disk


@pytest.mark.slow
@pytest.mark.parametrize("sample", SAMPLES, ids=[sample["file"] for sample in SAMPLES])
def test_the_oracles_give_each_sample_its_pinned_status(sample: dict, tmp_path: Path) -> None:  # type: ignore[type-arg]
    expected = {problem: status for problem, status in sample["status"].items() if problem in JUDGED}
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "grader.compat",
            str(JUDGE),
            str(ROOT / "submissions" / sample["file"]),
            sample["edition"],
            *expected,
        ],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout.strip().splitlines()[-1]) == expected
