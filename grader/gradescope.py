"""Gradescope: a report as Gradescope's ``results.json``, and the autograder zip that produces it.

Gradescope's specification (https://gradescope-autograders.readthedocs.io/en/latest/specs/) is declared
once, as the pydantic models below, so what gymgrade writes is checked against it when it is built.
"""

from __future__ import annotations

import io
import json
import os
import stat
import tomllib
import zipfile
from importlib.metadata import requires, version
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

import grader
from grader.batch import SUBMISSION_SUFFIXES
from grader.cli import isolation_lines, notebook_lines
from grader.report import Report

Visibility = Literal["hidden", "after_due_date", "after_published", "visible"]
DEFAULT_ROOT = Path("/autograder")
PREFERRED_STEM = "opengym"
"""The lab's file name: chosen when a submission holds several gradable files."""
PROJECT_PACKAGES = ("grader", "reference")
"""What the bundle installs on Gradescope: the grader and its oracles (the service is not needed)."""
BUNDLE_PYTHON = "python3.11"
BUNDLE_VENV = "/opt/gymgrade"


class GradescopeTest(BaseModel):
    """One entry of ``tests``: a problem of the lab."""

    model_config = ConfigDict(extra="forbid")

    name: str
    number: str
    score: float
    max_score: float
    status: Literal["passed", "failed"]
    output: str
    visibility: Visibility = "visible"


class GradescopeResults(BaseModel):
    """Gradescope's ``results.json``."""

    model_config = ConfigDict(extra="forbid")

    score: float
    execution_time: int = Field(description="Seconds, as Gradescope's schema gives it (an integer).")
    output: str
    output_format: Literal["text", "md", "html", "simple_format", "ansi"] = "text"
    visibility: Visibility = "visible"
    stdout_visibility: Visibility = "hidden"
    tests: list[GradescopeTest]


def results(report: Report, *, visibility: Visibility = "visible") -> GradescopeResults:
    """Gradescope's results for one report: a test per problem, the summary and the isolation as output.

    Args:
        report: The grading report.
        visibility: When students see the results.

    Returns:
        The results; ``score`` is the report's, so partial credit and zero-point problems add up as in
        the gradebook.
    """
    tests = [
        GradescopeTest(
            name=problem.title,
            number=str(index),
            score=problem.score,
            max_score=problem.max_score,
            # A skipped problem (worth nothing, not run) failed nothing; its output says it was not run.
            status="passed" if problem.status in ("passed", "skipped") else "failed",
            output=f"{problem.status}: {problem.feedback}"
            + (f"\n\nYour output:\n{problem.output}" if problem.output else ""),
            # A problem the assignment hides (or shows after the due date) stays so on Gradescope.
            visibility=visibility if problem.visibility == "visible" else problem.visibility,
        )
        for index, problem in enumerate(report.problems, start=1)
    ]
    # The grading seed stays the instructor's: every resubmission is graded on the same held-out starts.
    lines = [f"gymgrade {report.grader_version}, gymnasium {report.gymnasium_version}."]
    if report.notebook is not None:
        lines += notebook_lines(report.notebook)
    if report.submission_error is not None:
        lines.append(report.submission_error)
    lines += isolation_lines(report.isolation)
    lines += [f"Grader error (not your fault): {error}" for error in report.grader_errors]
    return GradescopeResults(
        score=report.score,
        execution_time=round(report.execution_time),
        output="\n".join(lines),
        visibility=visibility,
        tests=tests,
    )


def failed_run(message: str) -> GradescopeResults:
    """Results for a run that graded nothing (no file to grade, the grader could not start)."""
    return GradescopeResults(score=0.0, execution_time=0, output=message, tests=[])


def pick_submission(directory: Path) -> Path | str:
    """The file to grade in Gradescope's submission directory, or why there is none.

    One ``.py`` or ``.ipynb`` file is graded as it is; among several, the one named like the lab's
    ``opengym.py`` (or ``opengym.ipynb``) is chosen; otherwise the student is told what was found.
    """
    candidates = sorted(
        path
        for path in directory.rglob("*")
        if path.is_file()
        and path.suffix.lower() in SUBMISSION_SUFFIXES
        and not any(part.startswith(".") for part in path.relative_to(directory).parts)
    )
    if len(candidates) == 1:
        return candidates[0]
    preferred = [path for path in candidates if path.stem == PREFERRED_STEM]
    if len(preferred) == 1:
        return preferred[0]
    found = ", ".join(str(path.relative_to(directory)) for path in candidates) or "no .py or .ipynb file"
    return (
        f"Expected one Python file (.py) or Jupyter notebook (.ipynb) with your functions, ideally named {PREFERRED_STEM}.py; "  # noqa: E501
        f"found {found}. Submit exactly one such file."
    )


def bundle(out: Path, *, config: Path | None, seed: int) -> Path:
    """Write the Gradescope autograder zip.

    It holds ``setup.sh`` (Debian/Ubuntu packages, Python 3.11 and a virtualenv with this gymgrade),
    ``run_autograder``, the assignment configuration, and the source of this gymgrade's ``grader`` and
    ``reference`` packages with a minimal ``pyproject.toml`` (so the autograder grades exactly as this
    installation does, without reaching any package index for gymgrade itself).

    Args:
        out: The zip to write.
        config: Assignment configuration; the bundled one when None.
        seed: The grading seed every submission is graded with.

    Returns:
        ``out``.
    """
    config_text = (config or Path(grader.__file__).with_name("assignment.toml")).read_text(encoding="utf-8")
    source_root = Path(grader.__file__).resolve().parents[1]
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        _add(archive, "setup.sh", SETUP_SH, executable=True)
        _add(archive, "run_autograder", RUN_AUTOGRADER.format(seed=seed), executable=True)
        _add(archive, "assignment.toml", config_text)
        _add(archive, "gymgrade/pyproject.toml", _pyproject(_dependencies(source_root)))
        for package in PROJECT_PACKAGES:
            for path in sorted((source_root / package).rglob("*")):
                if path.is_file() and "__pycache__" not in path.parts and path.suffix != ".pyc":
                    relative = path.relative_to(source_root).as_posix()
                    _add(archive, f"gymgrade/{relative}", path.read_bytes())
    out.write_bytes(buffer.getvalue())
    return out


def _add(archive: zipfile.ZipFile, name: str, content: str | bytes, *, executable: bool = False) -> None:
    info = zipfile.ZipInfo(name, date_time=(2026, 1, 1, 0, 0, 0))
    mode = 0o755 if executable else 0o644
    info.external_attr = (stat.S_IFREG | mode) << 16
    info.compress_type = zipfile.ZIP_DEFLATED
    archive.writestr(info, content)


def _dependencies(source_root: Path) -> list[str]:
    """The project's runtime requirements: from its pyproject.toml in a source tree, else as installed."""
    pyproject = source_root / "pyproject.toml"
    if pyproject.is_file():
        declared: list[str] = tomllib.loads(pyproject.read_text(encoding="utf-8"))["project"]["dependencies"]
        return declared
    return [requirement for requirement in requires("gymgrade") or [] if "extra ==" not in requirement]


def _pyproject(dependencies: list[str]) -> str:
    listed = ",\n".join(f"    {json.dumps(requirement)}" for requirement in dependencies)
    return (
        '[build-system]\nrequires = ["setuptools>=69", "wheel"]\nbuild-backend = "setuptools.build_meta"\n\n'
        f'[project]\nname = "gymgrade"\nversion = "{version("gymgrade")}"\nrequires-python = ">=3.11"\n'
        f"dependencies = [\n{listed},\n]\n\n"
        '[project.scripts]\ngymgrade = "grader.cli:main"\n\n'
        '[tool.setuptools.packages.find]\ninclude = ["reference*", "grader*"]\n\n'
        '[tool.setuptools.package-data]\n"*" = ["*.toml", "*.ini", "*.md", "py.typed"]\n'
    )


def default_root() -> Path:
    """Gradescope's root, ``/autograder``, or ``GYMGRADE_AUTOGRADER_ROOT`` (tests use a temporary one)."""
    return Path(os.environ.get("GYMGRADE_AUTOGRADER_ROOT", str(DEFAULT_ROOT)))


def run_autograder(root: Path, *, seed: int, config: Path | None, workers: int | None) -> GradescopeResults:
    """Grade ``<root>/submission`` into ``<root>/results/results.json`` (what ``run_autograder`` runs).

    Never raises for a student's file: no file, a bad file, a crash are all results. The policy is
    ``ALLOW_FALLBACK``: Gradescope's containers do not allow every isolation layer (see the README), and
    the results' output names the missing ones.
    """
    from grader.grading import grade_submission
    from grader.sandbox import IsolationPolicy

    picked = pick_submission(root / "submission")
    if isinstance(picked, str):
        graded = failed_run(picked)
    else:
        try:
            report = grade_submission(
                picked, seed=seed, workers=workers, policy=IsolationPolicy.ALLOW_FALLBACK, config=config
            )
        except Exception as error:  # results.json must exist whatever happens, or Gradescope shows nothing
            graded = failed_run(
                f"The autograder failed (not your fault; please tell your instructor): "
                f"{type(error).__name__}: {error}"
            )
        else:
            graded = results(report)
    target = root / "results" / "results.json"
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(graded.model_dump_json(indent=2) + "\n", encoding="utf-8")
    return graded


SETUP_SH = f"""#!/usr/bin/env bash
# Gradescope setup: runs once, as root, on Gradescope's Ubuntu image, from /autograder/source.
set -euo pipefail
cd "$(dirname "$0")"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
# bubblewrap + libseccomp: the sandbox's namespaces and system-call filter (used where the container
# allows them); Python 3.11 from the distribution (Ubuntu 22.04's default python3 is 3.10).
apt-get install -y -qq --no-install-recommends bubblewrap libseccomp2 {BUNDLE_PYTHON} \\
  {BUNDLE_PYTHON}-venv ca-certificates >/dev/null
{BUNDLE_PYTHON} -m venv {BUNDLE_VENV}
{BUNDLE_VENV}/bin/python -m pip install --quiet --disable-pip-version-check --upgrade pip
{BUNDLE_VENV}/bin/python -m pip install --quiet --disable-pip-version-check ./gymgrade
{BUNDLE_VENV}/bin/gymgrade --help >/dev/null
"""

RUN_AUTOGRADER = """#!/usr/bin/env bash
# Gradescope runs this for every submission: grade /autograder/submission/* into
# /autograder/results/results.json. GYMGRADE_AUTOGRADER_ROOT and GYMGRADE_COMMAND move it (tests).
set -uo pipefail
root="${{GYMGRADE_AUTOGRADER_ROOT:-/autograder}}"
command="${{GYMGRADE_COMMAND:-/opt/gymgrade/bin/gymgrade}}"
# $command is split on spaces on purpose: tests pass "python3 -m grader.cli".
$command gradescope-run --root "$root" --seed {seed} --config "$root/source/assignment.toml"
"""
