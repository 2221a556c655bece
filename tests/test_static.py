"""The static checks, run by the suite so that CI holds them: ruff's lint rules and format, mypy's types.

Both tools are development dependencies (pyproject's `dev` extra, installed by scripts/setup.sh). The
configuration is pyproject's (`[tool.ruff]`, `[tool.mypy]`); these tests only run them on the whole tree.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
TYPED = ("grader", "api", "reference")
"""The packages mypy checks (tests, bench and scripts are linted, not type-checked)."""


def _run(*command: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", *command], cwd=ROOT, capture_output=True, text=True, timeout=600, check=False
    )


def test_ruff_finds_nothing() -> None:
    found = _run("ruff", "check", "--no-cache", ".")
    assert found.returncode == 0, f"expected no lint finding; ruff found:\n{found.stdout}{found.stderr}"


def test_ruff_format_would_change_nothing() -> None:
    found = _run("ruff", "format", "--check", "--no-cache", ".")
    assert found.returncode == 0, (
        f"expected every file formatted; run `ruff format .`:\n{found.stdout}{found.stderr}"
    )


@pytest.mark.slow
def test_mypy_finds_nothing() -> None:
    found = _run("mypy", *TYPED)
    assert found.returncode == 0, f"expected no type error; mypy found:\n{found.stdout}{found.stderr}"
