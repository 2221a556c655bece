"""Every honest notebook sample, exported as Jupyter's "Download as Python" (nbconvert's `ScriptExporter`, run
here) and Colab's "Download .py" (`notebook_exports.colab_export`) write it, gets the notebook's verdicts:
the same status and score for every problem, through the real sandbox. Two (whose cells have ``!`` and
``%`` lines) are graded also as their cells copied into a file as they are (`verbatim_export`).

The second lab has no notebook sample: its honest files are modules (graded as they are, as
`submissions/rl2/verdicts.toml` pins); its notebook and exports are here too, built from the 2024 module's
functions and demo cells (`RL2_NOTEBOOK`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import nbformat
import pytest
from grading_support import FAST_OVERRIDES, SUBMISSIONS, write_config
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook
from notebook_exports import colab_export, nbconvert_export, verbatim_export

from grader.grading.grade import grade_files
from grader.grading.plan import GradingPlan
from grader.lab.editions import edition_of
from grader.report import Report
from grader.sandbox import IsolationPolicy

pytestmark = [
    pytest.mark.slow,  # grades notebooks and their exports through the real sandbox
    pytest.mark.xdist_group("export-verdicts"),  # one worker grades `reports` for all
]

SEED = 20261207
LAB_EPISODES = "N=70_000"
OVERRIDES: dict[str, dict[str, Any]] = {
    **FAST_OVERRIDES,
    "blackjack": {"thresholds": [12]},
    "compare": {"cells_seconds": 3600.0},
}
RL1 = ("random_blackjack", "blackjack", "cartpole", "car", "epsilon_decay", "taxi", "sarsa0", "compare")


@dataclass(frozen=True)
class Case:
    """A notebook sample, the edition and problems it is graded on, its learners' episodes in the suite."""

    notebook: str
    edition: str
    problems: tuple[str, ...]
    suite_episodes: int | None = None
    verbatim: bool = False
    """Also graded as its code cells copied into a file as they are (its ``!`` and ``%`` lines not Python)."""

    def data(self) -> bytes:
        if self.notebook == RL2_NOTEBOOK:
            return _rl2_notebook()
        data = (SUBMISSIONS / self.notebook).read_bytes()
        if self.suite_episodes is not None:  # as tests/grader/lab/editions/test_edition_samples.py grades it
            data = data.replace(LAB_EPISODES.encode(), f"N={self.suite_episodes}".encode())
        return data


RL2_NOTEBOOK = "rl2/policy_iteration.ipynb (built from rl2/honest_v2024.py)"
CASES = [
    Case(
        "notebooks/classic_complete.ipynb", "classic", ("random_blackjack", "cartpole", "taxi"), verbatim=True
    ),
    Case("notebooks/bad_metadata.ipynb", "classic", ("random_blackjack", "cartpole")),
    Case("notebooks/old_format_v3.ipynb", "classic", ("cartpole",)),
    Case("editions/rl1_template_honest.ipynb", "rl1", RL1, suite_episodes=3000),
    Case("editions/compare_honest.ipynb", "rl1", ("compare",)),
    Case("templates/rl1.ipynb", "rl1", RL1),
    Case(
        RL2_NOTEBOOK,
        "v2024",
        ("value_iteration", "policy_iteration", "run_simulation", "frozen_lake"),
        verbatim=True,
    ),
]
EXPORTS = ("notebook", "nbconvert", "colab", "verbatim")


def _rl2_notebook() -> bytes:
    """The honest 2024 module as its notebook: a markdown title, the imports and the example MDP, one cell per
    function, and demo cells calling them (which the grader must not run at import)."""
    source = (SUBMISSIONS / "rl2" / "honest_v2024.py").read_text(encoding="utf-8")
    head, _, rest = source.partition("\ndef ")
    functions = ["def " + part for part in rest.split("\ndef ")]
    cells = [new_markdown_cell("# Policy Function Iteration")]
    cells.append(new_code_cell("%matplotlib inline\n" + head.strip()))
    for function in functions:
        cells.append(new_code_cell(function.strip()))
    cells.append(new_code_cell("V, n = value_iteration(P, 4, 4)\nprint(V, n)\n!echo done"))
    notebook = new_notebook(cells=cells)
    notebook.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    return nbformat.writes(notebook).encode("utf-8")


def _config(directory: Path, edition: str) -> Path:
    base = edition_of(edition).default_config
    present = base.read_text(encoding="utf-8")
    overrides = {name: fields for name, fields in OVERRIDES.items() if f"[problems.{name}]" in present}
    return write_config(directory / f"{edition}.toml", overrides, base=base)


@pytest.fixture(scope="module")
def reports(tmp_path_factory: pytest.TempPathFactory) -> dict[tuple[str, str], Report]:
    """Each case's reports: the notebook's and each export's, keyed by (notebook, export)."""
    directory = tmp_path_factory.mktemp("exports")
    found: dict[tuple[str, str], Report] = {}
    for index, case in enumerate(CASES):
        data = case.data()
        name = "policy_iteration" if case.edition.startswith("v") else "gymnasium"
        folder = directory / str(index)
        folder.mkdir()
        files = {
            "notebook": folder / f"{name}.ipynb",
            "nbconvert": folder / "nbconvert" / f"{name}.py",
            "colab": folder / "colab" / f"{name}.py",
        }
        for path in files.values():
            path.parent.mkdir(exist_ok=True)
        files["notebook"].write_bytes(data)
        files["nbconvert"].write_text(nbconvert_export(data), encoding="utf-8")
        files["colab"].write_text(colab_export(data, f"{name}.ipynb"), encoding="utf-8")
        if case.verbatim:
            files["verbatim"] = folder / "verbatim" / f"{name}.py"
            files["verbatim"].parent.mkdir()
            files["verbatim"].write_text(verbatim_export(data), encoding="utf-8")
        plan = GradingPlan.load(_config(directory, case.edition), case.problems)
        graded = grade_files(
            list(files.values()), plan, seed=SEED, workers=2, policy=IsolationPolicy.ALLOW_FALLBACK
        )
        found.update({(case.notebook, export): report for export, report in zip(files, graded, strict=True)})
    return found


GRADED = [(case, export) for case in CASES for export in EXPORTS[1:] if export != "verbatim" or case.verbatim]


@pytest.mark.parametrize(
    ("case", "export"), GRADED, ids=[f"{export}-{case.notebook}" for case, export in GRADED]
)
def test_an_export_gets_its_notebooks_verdicts(
    case: Case, export: str, reports: dict[tuple[str, str], Report]
) -> None:
    notebook, exported = reports[(case.notebook, "notebook")], reports[(case.notebook, export)]
    assert notebook.submission_error is None and exported.submission_error is None, exported.submission_error
    assert exported.grader_errors == []
    honest = "missing" if case.notebook.startswith("templates/") else "passed"  # what the exports are held to
    statuses = {problem.status for problem in notebook.problems}
    assert statuses == {honest}, [problem.feedback for problem in notebook.problems]
    verdicts = {problem.id: (problem.status, problem.score) for problem in notebook.problems}
    feedback = {problem.id: problem.feedback for problem in exported.problems}
    found = {problem.id: (problem.status, problem.score) for problem in exported.problems}
    assert found == verdicts, feedback
    assert exported.notebook is not None and exported.notebook.script  # read as its notebook, and said so
