"""`gymgrade doctor` names the interpreter, its binds, the layers and each student module's fate."""

from __future__ import annotations

import pytest

from grader.cli import main
from grader.lab.assignment import STUDENT_MODULES
from grader.sandbox.doctor import diagnose, render
from grader.sandbox.isolation.filesystem import python_paths


@pytest.mark.sandbox
def test_a_module_the_grader_lacks_is_named_with_its_remedy_and_the_machine_is_not_ready() -> None:
    diagnosis = diagnose(("tqdm", "gymgrade_no_such_module"))
    text = render(diagnosis)
    assert [(module.name, module.version is not None) for module in diagnosis.modules] == [
        ("tqdm", True),
        ("gymgrade_no_such_module", False),
    ]
    assert (
        "  [ ] gymgrade_no_such_module: No module named 'gymgrade_no_such_module' (ModuleNotFoundError) -- "
        in text
    )
    assert f"install it into the environment of {python_paths().executable}" in text
    assert not diagnosis.healthy and text.endswith("Verdict: NOT ready: fix what is marked [ ] above")


@pytest.mark.sandbox
def test_doctor_shows_interpreter_binds_layers_and_the_courses_modules(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code = main(["doctor"])
    text = capsys.readouterr().out
    paths = python_paths()
    assert text.startswith(f"Interpreter: {paths.executable} (Python ")
    assert all(f"\n  {entry}\n" in text for entry in paths.site_dirs)
    for name in ("cgroup", "bubblewrap", "seccomp", "privileges", "rlimits", "landlock"):
        assert f"] {name}: " in text
    assert all(f"  [x] {name} " in text for name in STUDENT_MODULES)
    assert (code, text.rstrip().splitlines()[-1]) == (0, "Verdict: ready to grade")
