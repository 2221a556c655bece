"""Tests for the fallback `IPython` (grader/compat/fallback): used only when IPython is missing."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest

from grader.compat import shim_paths


def _load_fallback_display() -> ModuleType:
    path = shim_paths().fallback / "IPython" / "display.py"
    spec = importlib.util.spec_from_file_location("gymgrade_fallback_ipython_display", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_clear_output_does_nothing_and_prints_nothing(capsys: pytest.CaptureFixture[str]) -> None:
    display = _load_fallback_display()
    assert display.clear_output(wait=True) is None
    assert display.clear_output() is None
    assert capsys.readouterr() == ("", "")


def test_display_prints_its_objects(capsys: pytest.CaptureFixture[str]) -> None:
    _load_fallback_display().display("Episode:", 100)
    assert capsys.readouterr().out == "Episode: 100\n"


HIDE_INSTALLED_IPYTHON = """
import sys
from importlib.machinery import PathFinder

class HideInstalledIPython:
    # Simulates a machine without IPython: only the layer's directories can provide it.
    @staticmethod
    def find_spec(name, path=None, target=None):
        if name.split(".")[0] != "IPython":
            return None
        search = path or [entry for entry in sys.path if "site-packages" not in entry]
        return PathFinder.find_spec(name, search) or ImportError
"""


@pytest.mark.parametrize("ipython_installed", [True, False], ids=["ipython-installed", "ipython-missing"])
def test_the_lab_import_works_and_a_real_ipython_wins(tmp_path: Path, ipython_installed: bool) -> None:
    code = (
        HIDE_INSTALLED_IPYTHON
        + f"""
if not {ipython_installed}:
    sys.meta_path.insert(0, HideInstalledIPython)
import grader.compat
grader.compat.activate()
from IPython.display import clear_output
for _ in range(1000):
    clear_output(wait=True)
import IPython
print("fallback" if IPython.__file__.startswith(str(grader.compat.shim_paths().fallback)) else "real")
"""
    )
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=60, check=False
    )
    assert result.returncode == 0, result.stderr
    real_available = importlib.util.find_spec("IPython") is not None
    expected = "real" if ipython_installed and real_available else "fallback"
    assert result.stdout.splitlines()[-1] == expected
