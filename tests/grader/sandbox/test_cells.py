"""The child's cells runner: cells run in order in the module's globals, a failing cell is named, learners'
tables are labelled (`grader.sandbox.child.cells`, run here in-process on a fresh module)."""

import importlib.util
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

from grader.sandbox.child.cells import MAX_TABLES, NotAttemptedError, NotebookCellError, run_cells


def _module() -> ModuleType:
    module = ModuleType("submission")
    module.__file__ = "/scratch/gymnasium.ipynb.py"
    return module


def _cells(*sources: str) -> list[dict[str, Any]]:
    return [{"cell": number, "source": source, "script": False} for number, source in enumerate(sources, 2)]


LEARNERS = """
import numpy as np

def qlearn(env, alpha=0.1, gamma=0.6, epsilon=0.1, N=70_000, decay=False):
    return np.full((500, 6), float(N)), 3

def sarsa0(env, alpha=0.1, gamma=0.6, epsilon=0.1, N=70_000, decay=False):
    return np.full((500, 6), -float(N))
"""


def test_cells_run_in_order_in_the_module_globals() -> None:
    module = _module()
    value = run_cells(module, _cells("x = 1", "x += 1\ny = x * 10"))
    assert (module.x, module.y) == (2, 20)
    assert [entry["cell"] for entry in value["cells"]] == [2, 3]
    assert all(entry["seconds"] >= 0 for entry in value["cells"])
    assert value["tables"] == []


def test_learner_tables_are_labelled_with_decay_and_n() -> None:
    module = _module()
    value = run_cells(
        module,
        _cells(
            LEARNERS,
            "q_table, _ = qlearn(None, N=10)\nq_table_decay, _ = qlearn(None, N=20, decay=True)",
            "store = {'sarsa': sarsa0(None, 0.1, 0.6, 0.1, 30, True)}",
        ),
    )
    found = {(table["learner"], table["decay"], table["N"]): table for table in value["tables"]}
    assert set(found) == {("qlearn", False, 10), ("qlearn", True, 20), ("sarsa0", True, 30)}
    assert found[("qlearn", True, 20)]["names"] == ["q_table_decay"]
    assert found[("sarsa0", True, 30)]["names"] == []  # kept though no global holds it
    assert float(found[("sarsa0", True, 30)]["table"][0, 0]) == -30.0
    assert module.qlearn.__name__ == "qlearn"  # the label keeps the learner's name and signature


def test_a_global_table_from_elsewhere_is_listed_unlabelled() -> None:
    value = run_cells(
        _module(), _cells("import numpy as np\nloaded = np.zeros((500, 6))\nsmall = np.zeros((5, 6))")
    )
    assert [(table["names"], table["learner"]) for table in value["tables"]] == [(["loaded"], None)]


def test_tables_are_capped() -> None:
    value = run_cells(
        _module(), _cells("import numpy as np\n" + "\n".join(f"t{i} = np.zeros((500, 6))" for i in range(40)))
    )
    assert len(value["tables"]) == MAX_TABLES


@pytest.mark.parametrize(
    ("sources", "message"),
    [
        (("x = 1", "y = 2\nz = undefined_name"), "cell 3 (line 2) raised NameError: name 'undefined_name' is not defined"),  # noqa: E501
        (("def f():\n    raise ValueError('bad')", "f()"), "cell 3 (line 1) raised ValueError: bad"),
        (("x = (",), "cell 2 (line 1) raised SyntaxError"),
        (("import sys\nsys.exit(3)",), "cell 2 (line 2) raised SystemExit: 3"),
    ],
    ids=["name_error", "error_in_a_function", "syntax_error", "exit"],
)  # fmt: skip
def test_the_first_failing_cell_stops_the_run_and_is_named(sources: tuple[str, ...], message: str) -> None:
    module = _module()
    with pytest.raises(NotebookCellError) as raised:
        run_cells(module, [*_cells(*sources), {"cell": 99, "source": "after = True", "script": False}])
    assert str(raised.value).startswith(message), str(raised.value)
    assert not hasattr(module, "after")


def test_a_script_runs_its_main_block() -> None:
    module = _module()
    source = "def f():\n    return 4\n\nif __name__ == '__main__':\n    table = f()\n"
    run_cells(module, [{"cell": 0, "source": source, "script": True}])
    assert module.table == 4
    assert module.__name__ == "submission"


def test_a_failing_script_names_the_file_and_line() -> None:
    with pytest.raises(
        NotebookCellError, match=r"^your file run as a script \(line 2\) raised KeyError: 'q'"
    ):
        run_cells(_module(), [{"cell": 0, "source": "tables = {}\ntables['q']", "script": True}])


def test_non_finite_tables_are_left_out() -> None:
    value = run_cells(_module(), _cells("import numpy as np\nbad = np.full((500, 6), np.nan)"))
    assert value["tables"] == []


@pytest.mark.parametrize(
    ("source", "message"),
    [
        ("x = 1", "your notebook defines no function `compare`, so its cells were not run"),
        (
            "def compare():\n    raise NotImplementedError('Problem 7')",
            "`compare` is still the template's stub",
        ),
    ],
    ids=["missing", "stub"],
)
def test_no_cell_runs_when_the_function_called_after_them_is_not_attempted(
    source: str, message: str, tmp_path: Path
) -> None:
    path = tmp_path / "gymnasium.ipynb.py"
    path.write_text(source + "\n", encoding="utf-8")
    spec = importlib.util.spec_from_file_location("submission_under_test", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)  # the stub's source is read from its file, as in the child
    with pytest.raises(NotAttemptedError, match=message):
        run_cells(module, _cells("ran = True"), then="compare")
    assert not hasattr(module, "ran")
