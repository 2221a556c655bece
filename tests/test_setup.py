"""scripts/setup.sh installs into the interpreter, or into a project virtualenv when that is managed."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

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


# End to end, as a newcomer does it (issue 26): a fresh copy of the project, the README's two commands,
# one cheap problem graded under the strongest isolation the machine offers. Each takes about a minute
# (pip installs from its cache or the local index).
SYSTEM_PYTHON = Path("/usr/bin/python3")
SYSTEM_PATH = "/usr/local/bin:/usr/bin:/bin"
UNPRIVILEGED_UID = 65534
CHEAP_CHECK = ["gymgrade", "check", "submissions/classic_complete.py", "--only", "random_blackjack", "--json"]


def _fresh_copy(destination: Path) -> Path:
    """The project's files as a fresh clone of this tree has them (edits included, ignored files not)."""
    listed = subprocess.run(
        ["git", "-C", str(ROOT), "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        capture_output=True, check=True,
    ).stdout.decode().split("\0")  # fmt: skip
    for name in filter(None, listed):
        source = ROOT / name
        if source.is_file():
            (destination / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, destination / name)
    return destination


def _newcomer_environment(home: Path | None = None) -> dict[str, str]:
    environment = {
        name: value for name, value in os.environ.items() if not name.startswith(("PYTHON", "VIRTUAL_ENV"))
    }
    environment.pop("GYMGRADE_USE_VENV", None)
    environment.pop("GYMGRADE_VENV", None)
    environment["PATH"] = SYSTEM_PATH
    if home is not None:
        environment |= {"HOME": str(home), "PIP_CACHE_DIR": str(home / ".cache" / "pip")}
    return environment


def _run(argv: list[str], project: Path, environment: dict[str, str], prefix: tuple[str, ...] = ()) -> str:
    result = subprocess.run(
        [*prefix, *argv], cwd=project, env=environment, capture_output=True, text=True, timeout=900
    )
    # setup.sh exits non-zero when any step fails (set -e); `gymgrade check` exits 0 on full marks,
    # which the one cheap problem of the lab-literal file earns: anything else is a failure here.
    assert result.returncode == 0, f"{argv} exited {result.returncode}:\n{result.stdout}\n{result.stderr}"
    return result.stdout


def _readme_commands(
    project: Path, environment: dict[str, str], prefix: tuple[str, ...] = ()
) -> dict[str, Any]:
    _run(["bash", "scripts/setup.sh"], project, environment, prefix)
    return json.loads(_run(["scripts/run", *CHEAP_CHECK], project, environment, prefix))


def _debian_python() -> str | None:
    """Why Debian's own python3 cannot be tried here, or None."""
    if not SYSTEM_PYTHON.exists() or shutil.which("apt-get") is None:
        return "needs a Debian or Ubuntu machine with /usr/bin/python3"
    version = subprocess.run([str(SYSTEM_PYTHON), "-c", "import sys; print(sys.version_info >= (3, 11))"],
                             capture_output=True, text=True, check=True).stdout.strip()  # fmt: skip
    return (
        None if version == "True" else "needs the distribution's python3 >= 3.11 (Debian 12, Ubuntu 23.04+)"
    )


@pytest.mark.slow
@pytest.mark.install
@pytest.mark.xdist_group("install")  # one setup.sh at a time, and first: the longest tests
@pytest.mark.sandbox
def test_debians_python3_first_on_path_grades_with_full_isolation(tmp_path: Path) -> None:
    reason = _debian_python()
    if reason is not None:
        pytest.skip(reason)
    report = _readme_commands(_fresh_copy(tmp_path / "fresh"), _newcomer_environment())
    assert (tmp_path / "fresh" / ".venv" / "bin" / "gymgrade").exists()  # PEP 668: installed into .venv
    assert [(p["id"], p["status"]) for p in report["problems"]] == [("random_blackjack", "passed")]
    assert report["isolation"]["full"] is (os.geteuid() == 0), report["isolation"]["summary"]


@pytest.mark.slow
@pytest.mark.install
@pytest.mark.xdist_group("install")  # one setup.sh at a time, and first: the longest tests
@pytest.mark.sandbox
def test_a_virtualenv_under_tmp_grades_with_full_isolation(tmp_path: Path) -> None:
    project = _fresh_copy(tmp_path / "fresh")
    venv = tmp_path / "venv"  # pytest's tmp_path is under /tmp, like CI's and pipx's virtualenvs
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=120)
    environment = _newcomer_environment() | {"PYTHON": str(venv / "bin" / "python")}
    environment["PATH"] = f"{venv / 'bin'}:{SYSTEM_PATH}"
    report = _readme_commands(project, environment)
    assert not (project / ".venv").exists()  # a virtualenv's python is not externally managed
    assert [(p["id"], p["status"]) for p in report["problems"]] == [("random_blackjack", "passed")]
    assert report["isolation"]["full"] is (os.geteuid() == 0), report["isolation"]["summary"]


@pytest.mark.slow
@pytest.mark.install
@pytest.mark.xdist_group("install")  # one setup.sh at a time, and first: the longest tests
@pytest.mark.sandbox
@pytest.mark.expected_skip("already unprivileged")  # the test that runs as root drops to another user
def test_an_unprivileged_user_grades_with_the_strongest_isolation_available_and_names_the_rest() -> None:
    reason = _debian_python()
    if reason is not None:
        pytest.skip(reason)
    if os.geteuid() != 0:
        pytest.skip("already unprivileged: the Debian test above runs as this user")
    home = Path(tempfile.mkdtemp(prefix="gymgrade-laptop-", dir="/tmp"))  # not pytest's 0700 tmp_path
    try:
        project = _fresh_copy(home / "fresh")
        subprocess.run(["chown", "-R", f"{UNPRIVILEGED_UID}:{UNPRIVILEGED_UID}", str(home)], check=True)
        as_user = ("setpriv", f"--reuid={UNPRIVILEGED_UID}", f"--regid={UNPRIVILEGED_UID}", "--clear-groups")
        environment = _newcomer_environment(home)
        report = _readme_commands(project, environment, as_user)
        assert [(p["id"], p["status"]) for p in report["problems"]] == [("random_blackjack", "passed")]
        layers = {layer["name"]: layer for layer in report["isolation"]["layers"]}
        assert layers["bubblewrap"]["active"] and layers["seccomp"]["active"], report["isolation"]["summary"]
        missing = [layer for layer in layers.values() if layer["required"] and not layer["active"]]
        assert all(layer["detail"] and layer["remedy"] for layer in missing), report["isolation"]["summary"]
        doctor = subprocess.run(
            [*as_user, "scripts/run", "gymgrade", "doctor"], cwd=project, env=environment,
            capture_output=True, text=True, timeout=300,
        )  # fmt: skip
        assert f"Interpreter: {SYSTEM_PYTHON.resolve()} " in doctor.stdout, doctor.stdout + doctor.stderr
        assert "[x] bubblewrap: " in doctor.stdout and "  [x] tqdm " in doctor.stdout
        assert (doctor.returncode == 0) is not missing
    finally:
        shutil.rmtree(home, ignore_errors=True)
