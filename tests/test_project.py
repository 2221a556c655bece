"""Project-level promises: the README's test command is what CI runs."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _readme_commands() -> list[str]:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    return re.findall(r"```\n(bash scripts/setup\.sh && [^\n]+)\n```", readme)


def test_readme_has_a_setup_and_main_job_command_and_a_test_command() -> None:
    commands = _readme_commands()
    assert len(commands) == 2, f"expected the README's two set-up commands, found {commands}"
    # `-m ""` lifts the default run's selection (pyproject addopts): the test command runs every test.
    assert commands[1].endswith('python3 -m pytest -m ""'), commands[1]


def test_ci_runs_exactly_the_readme_test_command() -> None:
    test_command = _readme_commands()[1]
    ci_lines = [
        line.strip()
        for line in (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
        if line.strip() and not line.lstrip().startswith(("#", "set ", "cd "))
    ]
    assert ci_lines == [test_command]
