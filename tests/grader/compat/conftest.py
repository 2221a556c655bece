"""Run lab-literal scripts through the layer in a fresh interpreter, so `gym` never enters this process."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from collections.abc import Callable
from pathlib import Path

import pytest

RunScript = Callable[..., subprocess.CompletedProcess[str]]


@pytest.fixture
def run_through_layer(tmp_path: Path) -> RunScript:
    """Return `run(code, *args)`: write `code` to a script and run `python -m grader.compat script args`."""

    def run(code: str, *args: str, timeout: float = 60) -> subprocess.CompletedProcess[str]:
        script = tmp_path / "snippet.py"
        script.write_text(textwrap.dedent(code))
        return subprocess.run(
            [sys.executable, "-m", "grader.compat", str(script), *args],
            capture_output=True,
            text=True,
            cwd=tmp_path,
            timeout=timeout,
            check=False,
        )

    return run
