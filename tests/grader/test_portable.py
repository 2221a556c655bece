"""`gymgrade check` on students' laptops: Windows- and macOS-shaped interpreters give this machine's verdicts.

No Windows or macOS machine runs here, so each shaped run uses this machine's CPython shaped like the
other system's (`tests/grader/shaped_python/`): every process of the run starts shaped. The runs go
through `python -m grader` (what Windows users fall back to), from a directory named `Zoë`, with a
non-UTF-8 locale (`LANG=C`, no PYTHONIOENCODING; the Windows shape also opens text and writes its
streams as cp1252). What they cannot show (Windows' pipes, files held open, the console) is run by
`.github/workflows/portable.yml` on real runners.

One `check` per edition and shape (the complete sample of every edition and the classic notebook, with
a markdown cell of non-ASCII text), compared with this machine's run at the same seed: statuses,
scores and measurements identical. A function that never returns times out at its call limit on both.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from shaped_python import shaped_python

from grader.sandbox.host import HOST

ROOT = Path(__file__).resolve().parents[2]
SUBMISSIONS = ROOT / "submissions"
SHAPES = ("windows", "macos")
SEED = 0
HUNG_CALL_SECONDS = 5.0
CASES = (
    ("classic", "classic_complete.py"),
    ("gym026", "gym026_complete.py"),
    ("volume2", "gymnasium_complete.py"),
    ("rl1", "editions/rl1_complete.py"),
    ("classic", "notebooks/classic_complete.ipynb"),
)
FULL_MARKS = ("passed", "skipped")
"""Statuses of a complete solution ("skipped": not run, as find_qvalues is unless a verdict needs it)."""
NON_ASCII_NOTE = "Notes by Zoë: ε-greedy, Q ← Q + α·δ ✓"


def _place(sample: str, directory: Path) -> Path:
    """A copy of the sample under `directory`; a notebook gets a markdown cell of non-ASCII text."""
    source = SUBMISSIONS / sample
    target = directory / source.name
    if source.suffix == ".ipynb":
        notebook = json.loads(source.read_text(encoding="utf-8"))
        notebook["cells"].insert(0, {"cell_type": "markdown", "metadata": {}, "source": [NON_ASCII_NOTE]})
        target.write_text(json.dumps(notebook, ensure_ascii=False), encoding="utf-8")
    else:
        target.write_bytes(source.read_bytes())
    return target


def _check(python: Path | str, submission: Path, edition: str, *extra: str) -> dict[str, Any]:
    environment = {key: value for key, value in os.environ.items() if not key.startswith(("PYTHON", "LC_"))}
    environment.update(LANG="C", PATH=f"{Path(python).parent}{os.pathsep}/usr/bin{os.pathsep}/bin")
    if Path(python) == Path(sys.executable):
        environment["PATH"] = os.environ["PATH"]
    completed = subprocess.run(
        [
            str(python),
            "-m",
            "grader",
            "check",
            str(submission),
            "--json",
            "--edition",
            edition,
            "--seed",
            str(SEED),
            *extra,
        ],
        capture_output=True,
        cwd=submission.parent,
        env=environment,
        timeout=900,
        check=False,
    )
    if completed.returncode not in (0, 1):
        raise AssertionError(
            f"check ended with {completed.returncode}: {completed.stderr.decode('utf-8', 'replace')[-3000:]}"
        )
    report: dict[str, Any] = json.loads(completed.stdout.decode("utf-8"))
    return report


def _verdicts(report: dict[str, Any]) -> dict[str, tuple[Any, ...]]:
    """Per problem: status, score and measurements (what must not depend on the system)."""
    return {
        problem["id"]: (problem["status"], problem["score"], problem.get("measurements"))
        for problem in report["problems"]
    }


@pytest.fixture(scope="module")
def pythons(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The shaped interpreters on Linux; on another system (the CI runners), its own interpreter."""
    if HOST.system != "Linux":
        return {HOST.system: Path(sys.executable)}
    root = tmp_path_factory.mktemp("shaped")
    return {shape: shaped_python(root / shape, shape) for shape in SHAPES}


@pytest.mark.slow
@pytest.mark.expected_skip("shapes this Linux CPython")
@pytest.mark.skipif(HOST.system != "Linux", reason="shapes this Linux CPython; CI compares real runs")
def test_shaped_checks_give_the_linux_verdicts(pythons: dict[str, Path], tmp_path: Path) -> None:
    directory = tmp_path / "Zoë"
    directory.mkdir()
    differences = []
    for edition, sample in CASES:
        submission = _place(sample, directory)
        linux = _check(sys.executable, submission, edition)
        expected = _verdicts(linux)
        assert expected and all(status in FULL_MARKS for status, _, _ in expected.values()), (
            sample,
            expected,
        )
        for shape, python in pythons.items():
            report = _check(python, submission, edition)
            if _verdicts(report) != expected:
                differences.append((shape, sample, _verdicts(report), expected))
            missing = {
                layer["name"]: layer["detail"]
                for layer in report["isolation"]["layers"]
                if not layer["active"]
            }
            assert {"cgroup", "bubblewrap", "seccomp", "landlock"} <= set(missing), (shape, missing)
            assert all(
                "not available on this system" in missing[name] for name in ("cgroup", "bubblewrap")
            ), missing
            if shape == "windows":
                assert "rlimits" in missing and "privileges" in missing, missing
    assert not differences, differences


@pytest.mark.slow
def test_a_hung_function_times_out_at_its_limit_on_every_shape(
    pythons: dict[str, Path], tmp_path: Path
) -> None:
    directory = tmp_path / "Zoë"
    directory.mkdir()
    source = (SUBMISSIONS / "classic_complete.py").read_text(encoding="utf-8")
    hung = source.replace(
        "def random_blackjack(",
        "def random_blackjack(*args):\n    while True:\n        pass\n\n\ndef _was_random_blackjack(",
        1,
    )
    submission = directory / "opengym.py"
    submission.write_text(hung, encoding="utf-8")
    config_text = (ROOT / "grader" / "lab" / "assignment.toml").read_text(encoding="utf-8")
    config_text, replaced = re.subn(
        r"(\[problems\.random_blackjack\][^\[]*?call_seconds = )[0-9.]+",
        rf"\g<1>{HUNG_CALL_SECONDS}",
        config_text,
        count=1,
    )
    assert replaced == 1
    config = directory / "assignment.toml"
    config.write_text(config_text, encoding="utf-8")
    for shape, python in pythons.items():
        report = _check(python, submission, "classic", "--only", "random_blackjack", "--config", str(config))
        (problem,) = report["problems"]
        assert problem["status"] != "passed" and problem["score"] == 0, (shape, problem)
        assert f"did not return within {HUNG_CALL_SECONDS:g}" in problem["feedback"], (
            shape,
            problem["feedback"],
        )
