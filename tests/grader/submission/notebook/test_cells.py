"""The cells a problem that runs the notebook runs (`grader.submission.notebook.cells`): every code cell Run
All runs, as IPython would read it, kept beside the graded module; a `.py` runs whole as a script."""

from __future__ import annotations

from pathlib import Path

import nbformat
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook

from grader.grading.outcomes import with_notebook
from grader.report import ProblemResult, Report
from grader.submission.notebook import NotebookModule, build_module
from grader.submission.notebook.cells import RAN_CELLS, cells_path, runnable_cells, write_cells


def _notebook(*cells: object) -> bytes:
    return nbformat.writes(new_notebook(cells=list(cells))).encode()


def _built(data: bytes) -> NotebookModule:
    built = build_module(data, "gymnasium.ipynb", None)
    assert isinstance(built, NotebookModule), built
    return built


def test_every_code_cell_run_all_runs_is_kept_in_order_as_python() -> None:
    built = _built(
        _notebook(
            new_markdown_cell("# Lab"),
            new_code_cell("%matplotlib inline\nimport numpy as np"),
            new_code_cell("def compare():\n    return table.sum(), 0"),
            new_code_cell("%%bash\necho hi"),
            new_code_cell("%%time\ntable = np.ones((2, 2))\n!pip install gym"),
            new_code_cell("print(compare())"),
        )
    )
    numbers = [number for number, _ in built.cells]
    assert numbers == [2, 3, 5, 6]  # the %%bash cell is not Python: Jupyter's kernel would not run it as such
    sources = dict(built.cells)
    assert sources[2] == "pass\nimport numpy as np"
    assert sources[5] == "\ntable = np.ones((2, 2))\npass"
    assert sources[6] == "print(compare())"
    namespace: dict[str, object] = {}
    for _, source in built.cells:
        exec(compile(source, "<cell>", "exec"), namespace)
    assert namespace["table"].sum() == 4  # type: ignore[attr-defined]


def test_a_cell_that_is_not_python_is_kept_so_running_it_fails_there() -> None:
    built = _built(_notebook(new_code_cell("def f():\n    return 1"), new_code_cell("x = (")))
    assert [number for number, _ in built.cells] == [1, 2]


def test_cells_are_kept_beside_the_module_and_read_back(tmp_path: Path) -> None:
    module = tmp_path / "gymnasium.ipynb.py"
    module.write_text("x = 1\n", encoding="utf-8")
    write_cells(module, ((2, "x = 2"), (4, "y = x")))
    assert cells_path(module).name == "gymnasium.ipynb.py.cells.json"
    assert runnable_cells(module) == [
        {"cell": 2, "source": "x = 2", "script": False},
        {"cell": 4, "source": "y = x", "script": False},
    ]


def test_a_python_file_runs_whole_as_a_script(tmp_path: Path) -> None:
    module = tmp_path / "opengym.py"
    module.write_text("def f():\n    return 1\n", encoding="utf-8")
    assert runnable_cells(module) == [{"cell": 0, "source": "def f():\n    return 1\n", "script": True}]


def _report(result: ProblemResult) -> Report:
    return Report(
        submission="gymnasium.ipynb",
        sha256="0" * 64,
        seed=0,
        gymnasium_version="1",
        grader_version="1",
        problems=[result],
        score=0.0,
        max_score=1.0,
    )


def test_no_skipped_global_note_once_the_cells_ran_or_when_not_run() -> None:
    built = _built(
        _notebook(
            new_code_cell("def compare():\n    return q_table_decay"),
            new_code_cell("q_table_decay = train()"),
        )
    )
    assert built.summary.notes_for("compare")
    base = {"id": "compare", "title": "compare", "score": 0.0, "max_score": 1.0, "feedback": "F.", "seed": 0}
    ran = ProblemResult(**base, status="passed", measurements={RAN_CELLS: True})
    skipped = ProblemResult(**base, status="skipped", measurements={})
    called = ProblemResult(**base, status="error", measurements={})
    feedback = [
        with_notebook(_report(result), built).problems[0].feedback for result in (ran, skipped, called)
    ]
    assert feedback[:2] == ["F.", "F."]
    assert "q_table_decay" in feedback[2]
