"""Tests for grader.compat.activation and `python -m grader.compat`: only the layer's code sees gym."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import grader.compat
from grader.compat import events, format_summary, shim_paths
from grader.compat.events import CompatEvent

from .conftest import RunScript

COMPAT_DIR = Path(grader.compat.__file__).resolve().parent


def _python(code: str, *, cwd: Path, isolated: bool = False) -> subprocess.CompletedProcess[str]:
    flags = ["-I", "-B"] if isolated else []
    return subprocess.run(
        [sys.executable, *flags, "-c", code], capture_output=True, text=True, cwd=cwd, timeout=60, check=False
    )


def test_shim_paths_hold_the_gym_shim_first_and_the_ipython_fallback() -> None:
    paths = shim_paths()
    assert (paths.first / "gym" / "__init__.py").is_file()
    assert (paths.fallback / "IPython" / "display.py").is_file()


def test_importing_grader_compat_and_reference_installs_no_gym_and_registers_nothing(tmp_path: Path) -> None:
    code = """
import importlib.util, json, sys
genuine = importlib.util.find_spec("gym") is not None
import grader, grader.compat, reference
import gymnasium
try:
    import gym
    origin = gym.__file__
except ImportError:
    origin = None
print(json.dumps({"genuine": genuine, "origin": origin, "registered": "NChain-v0" in gymnasium.envs.registry,
                  "ipython_fallback": any("fallback" in entry for entry in sys.path)}))
"""
    result = _python(code, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout)
    if report["genuine"]:
        assert str(COMPAT_DIR) not in report["origin"]
    else:
        assert report["origin"] is None
    assert (report["registered"], report["ipython_fallback"]) == (False, False)


def test_activate_is_idempotent(tmp_path: Path) -> None:
    code = """
import sys, grader.compat
before = list(sys.path)
grader.compat.activate(); grader.compat.activate()
added = [entry for entry in sys.path if entry not in before]
paths = grader.compat.shim_paths()
assert added == [str(paths.first), str(paths.fallback)], added
assert sys.path[0] == str(paths.first) and sys.path[-1] == str(paths.fallback)
import gym
assert gym.__file__.startswith(str(paths.first)), gym.__file__
print("ok")
"""
    result = _python(code, cwd=tmp_path)
    assert (result.returncode, result.stdout.strip()) == (0, "ok"), result.stderr


@pytest.mark.slow
def test_the_layer_works_alone_from_a_read_only_copy(tmp_path: Path) -> None:
    """grader/compat bound alone (empty grader/__init__.py), no bytecode written, no other project code."""
    copy = tmp_path / "bound" / "grader"
    shutil.copytree(COMPAT_DIR, copy / "compat", ignore=shutil.ignore_patterns("__pycache__"))
    (copy / "__init__.py").write_text("")
    files_before = sorted(str(path) for path in copy.rglob("*"))
    code = f"""
import sys
sys.path.insert(0, {str(copy.parent)!r})
import grader.compat
grader.compat.activate()
import gym
from IPython.display import clear_output
env = gym.make("NChain-v0"); env.reset(); env.step(0)
env = gym.make("GuessingGame-v0"); env.reset(); env.step([0.0])
env = gym.make("Blackjack-v0"); env.step(0)
clear_output(wait=True)
foreign = sorted(name for name in ("reference", "api", "pydantic", "fastapi") if name in sys.modules)
assert foreign == [], foreign
assert grader.__file__.startswith({str(copy)!r}) and gym.__file__.startswith({str(copy)!r}), gym.__file__
print("ok")
"""
    result = _python(code, cwd=tmp_path, isolated=True)
    assert (result.returncode, result.stdout.splitlines()[-1]) == (0, "ok"), result.stderr
    assert sorted(str(path) for path in copy.rglob("*")) == files_before


def test_python_m_runs_the_script_as_main_with_its_args_and_summarises_events(
    run_through_layer: RunScript,
) -> None:
    result = run_through_layer(
        """
        import sys
        import gym
        env = gym.make("Taxi-v3")
        env.seed(1)
        print(__name__, sys.argv[1:], env.reset() == env.reset(seed=1))
        """,
        "--episodes",
        "3",
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout == "__main__ ['--episodes', '3'] True\n"
    assert result.stderr.splitlines()[0] == "gymgrade compat: 3 compatibility event(s)"
    assert result.stderr.splitlines()[1].startswith("  renamed_id [Taxi-v3]: Taxi-v3 was made as")
    assert result.stderr.splitlines()[2].startswith("  legacy_seed_call [Taxi-v3]: env.seed()")
    assert result.stderr.splitlines()[3] == (
        "  api_detected [Taxi-v3]: snippet.py was served the classic gym API (4-value step): line 5: "
        "env.seed() (classic seeding)"
    )


def test_python_m_keeps_the_script_s_exit_status_and_still_summarises(run_through_layer: RunScript) -> None:
    result = run_through_layer("import sys\nsys.exit(3)\n")
    assert (result.returncode, result.stderr) == (3, "gymgrade compat: no compatibility events\n")


def test_python_m_shows_the_script_s_traceback(run_through_layer: RunScript) -> None:
    result = run_through_layer("import gym\ngym.make('Taxi-v2')\n")
    assert result.returncode == 1
    assert (
        "RetiredEnvironmentError: gym.make('Taxi-v2'): Taxi-v2 was retired before this lab; "
        "the lab uses Taxi-v3. Write gym.make('Taxi-v3')." in result.stderr
    )


@pytest.mark.parametrize(
    ("args", "status", "stderr_start"),
    [
        ([], 2, "usage: python -m grader.compat SCRIPT.py [ARGS...]"),
        (
            ["missing.py"],
            2,
            "usage: python -m grader.compat SCRIPT.py [ARGS...]\nerror: expected a Python file",
        ),
    ],
    ids=["no-script", "missing-script"],
)
def test_python_m_usage_errors(tmp_path: Path, args: list[str], status: int, stderr_start: str) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "grader.compat", *args],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=60,
        check=False,
    )
    assert result.returncode == status and result.stderr.startswith(stderr_start)


def test_summary_lists_each_event() -> None:
    events.drain()
    assert (
        format_summary([CompatEvent("numpy_action", "Taxi-v3", "converted (5 times)")])
        == "gymgrade compat: 1 compatibility event(s)\n  numpy_action [Taxi-v3]: converted (5 times)"
    )
