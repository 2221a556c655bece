"""scripts/setup.sh installs into the interpreter, or into a project virtualenv when that is managed."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_setup_installs_into_a_project_virtualenv_that_scripts_run_uses(tmp_path: Path) -> None:
    # GYMGRADE_USE_VENV=1 takes the path an externally managed (PEP 668) python3 takes.
    venv = tmp_path / "venv"
    environment = {**os.environ, "GYMGRADE_USE_VENV": "1", "GYMGRADE_VENV": str(venv)}
    environment.pop("PYTHONPATH", None)
    setup = subprocess.run(
        ["bash", str(ROOT / "scripts" / "setup.sh")], env=environment, capture_output=True, text=True,
        timeout=900,
    )  # fmt: skip
    assert setup.returncode == 0, setup.stderr
    assert f"installed into the project virtualenv {venv}" in setup.stderr
    found = subprocess.run(
        [str(ROOT / "scripts" / "run"), "sh", "-c", "command -v gymgrade; command -v python3; "
         "gymgrade --help"],
        env=environment, capture_output=True, text=True, check=True, timeout=120,
    ).stdout.splitlines()  # fmt: skip
    assert found[:2] == [str(venv / "bin" / "gymgrade"), str(venv / "bin" / "python3")]
    assert any("gradescope-bundle" in line for line in found)


def test_run_leaves_the_path_alone_without_a_project_virtualenv(tmp_path: Path) -> None:
    environment = {**os.environ, "GYMGRADE_VENV": str(tmp_path / "none")}
    path = subprocess.run(
        [str(ROOT / "scripts" / "run"), "sh", "-c", 'printf %s "$PATH"'],
        env=environment, capture_output=True, text=True, check=True,
    ).stdout  # fmt: skip
    assert path == os.environ["PATH"]
