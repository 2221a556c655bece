"""The second lab through the real command line: `gymgrade check FILE --edition NAME` grades each edition's
reference in full marks and its template `missing` everywhere; hostile files fail or error, described."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from grader import cli
from grader.lab.rl2.editions import EDITIONS, V2024

ROOT = Path(__file__).resolve().parents[4]
NAMES = [edition.name for edition in EDITIONS]


@pytest.mark.slow  # a grading through the sandbox, in a child process as a person runs it
def test_gymgrade_check_grades_the_2024_honest_file_end_to_end(tmp_path: Path) -> None:
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "grader",
            "check",
            str(ROOT / "submissions/rl2/honest_v2024.py"),
            "--edition",
            "v2024",
        ],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=600,
        check=False,
    )
    assert result.returncode == cli.EXIT_FULL_MARKS, result.stderr
    assert (
        "Edition: v2024 (Reinforcement Learning 2: Markov Decision Process (2024)): chosen with --edition."
        in result.stderr
    )
    assert "Score: 7 / 7  (full marks)" in result.stdout
    for problem in V2024.registry.ids:
        assert f"{problem}: passed" in result.stdout


def _check(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, dict[str, str], dict[str, str]]:
    code = cli.main(["check", *argv, "--format", "json", "--workers", "2"])
    report = json.loads(capsys.readouterr().out)
    statuses = {problem["id"]: problem["status"] for problem in report["problems"]}
    feedback = {problem["id"]: problem["feedback"] for problem in report["problems"]}
    assert report["edition"] == argv[argv.index("--edition") + 1]
    return code, statuses, feedback


@pytest.mark.slow  # one grading per edition through the sandbox
@pytest.mark.parametrize("name", NAMES)
def test_each_editions_reference_passes_and_its_template_is_missing(
    name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    edition = next(edition for edition in EDITIONS if edition.name == name)
    code, statuses, feedback = _check(capsys, str(edition.reference), "--edition", name)
    assert (code, set(statuses.values())) == (cli.EXIT_FULL_MARKS, {"passed"}), feedback
    assert tuple(statuses) == edition.registry.ids
    code, statuses, feedback = _check(capsys, str(edition.template), "--edition", name)
    assert (code, set(statuses.values())) == (cli.EXIT_NOT_FULL, {"missing"}), feedback
    assert all("not attempted yet" in text for text in feedback.values()), feedback


HOSTILE = {
    "rigged_float": (
        """
        import numpy as np

        class Always(float):
            def __eq__(self, other):
                return True
            def __lt__(self, other):
                return True
            __hash__ = float.__hash__

        def value_iteration(P, nS, nA, beta=1.0, tol=1e-8, maxiter=3000):
            return [Always(0.0)] * nS, 3
        """,
        "error",
        "subclasses are refused because they can change comparisons",
    ),
    "huge_array": (
        """
        import numpy as np

        def value_iteration(P, nS, nA, beta=1.0, tol=1e-8, maxiter=3000):
            return np.zeros(10_000_000), 3
        """,
        "error",
        "more than the limit of",
    ),
    "hard_coded_example": (
        """
        import numpy as np

        def value_iteration(P, nS, nA, beta=1.0, tol=1e-8, maxiter=3000):
            return np.array([1.0, 1.0, 1.0, 0.0]) * [beta, 1, 1, 1], 3
        """,
        "failed",
        "FrozenLake 4x4 (slippery)",
    ),
    "plays_an_env": (
        """
        import gymnasium as gym

        def value_iteration(P, nS, nA, beta=1.0, tol=1e-8, maxiter=3000):
            env = gym.make("FrozenLake-v1")
            env.reset(seed=0)
            return [0.0] * nS, 3
        """,
        "failed",
        "the grader records at most 0 resets",
    ),
}


@pytest.mark.slow  # a grading through the sandbox per file
@pytest.mark.parametrize("name", list(HOSTILE))
def test_a_hostile_value_iteration_is_refused_described(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    source, status, found = HOSTILE[name]
    path = tmp_path / "policy_iteration.py"
    path.write_text(textwrap.dedent(source), encoding="utf-8")
    code, statuses, feedback = _check(capsys, str(path), "--edition", "v2024", "--only", "value_iteration")
    assert code == cli.EXIT_NOT_FULL
    assert statuses == {"value_iteration": status}, feedback
    assert found in feedback["value_iteration"], feedback
