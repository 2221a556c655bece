"""The child's table binding: which globals compare() reads, which learner each is, and when binding cannot
serve and the cells run instead (`grader.sandbox.child.binding`, through `run_cells`, in-process)."""

from types import ModuleType
from typing import Any

import numpy as np
import pytest

from grader.sandbox.child.binding import globals_loaded
from grader.sandbox.child.cells import NotebookCellError, run_cells

TABLES = {
    learner: {
        schedule: np.full((500, 6), float(index)) for index, schedule in enumerate(("decay", "constant"))
    }
    for learner in ("qlearn", "sarsa0")
}
TABLES["sarsa0"] = {schedule: table + 10.0 for schedule, table in TABLES["sarsa0"].items()}
"""Told apart by value: qlearn decay 0, constant 1; sarsa0 decay 10, constant 11."""

FUNCTIONS = """
import numpy as np

def qlearn(env, alpha=0.1, gamma=0.6, epsilon=0.1, N=70_000, decay=False):
    return np.zeros((500, 6)), 0

def sarsa0(env, alpha=0.1, gamma=0.6, epsilon=0.1, N=70_000, decay=False):
    return np.zeros((500, 6))

def play(table):
    return float(table[0, 0])
"""

TEMPLATE_COMPARE = """
def compare():
    return play(q_table_decay), play(sarsa_table_decay)
"""


def _module(*sources: str) -> ModuleType:
    module = ModuleType("submission")
    module.__file__ = "/scratch/gymnasium.ipynb.py"
    for source in sources:
        exec(compile(source, "<import>", "exec"), vars(module))
    return module


def _cells(*sources: str) -> list[dict[str, Any]]:
    return [{"cell": number, "source": source, "script": False} for number, source in enumerate(sources, 2)]


def _bound(module: ModuleType, *cells: str) -> dict[str, Any]:
    return run_cells(module, _cells(*cells), then="compare", bind=TABLES)


def test_the_templates_training_statements_say_which_table_is_which() -> None:
    module = _module(FUNCTIONS, TEMPLATE_COMPARE)
    value = _bound(
        module,
        'q_table, _ = qlearn("Taxi-v3")',
        'q_table_decay, _ = qlearn("Taxi-v3", decay=True)',
        'sarsa_table_decay = sarsa0("Taxi-v3", decay=True)',
        "ran = True",
    )
    assert "ran" not in vars(module)  # no cell ran
    assert value["cells"] == [] and value["tables"] == []
    assert {entry["name"]: (entry["learner"], entry["decay"], entry["read"]) for entry in value["bound"]} == {
        "q_table_decay": ("qlearn", True, True),
        "sarsa_table_decay": ("sarsa0", True, True),
        "q_table": ("qlearn", False, False),
    }
    assert module.compare() == (0.0, 10.0)
    assert module.q_table[0, 0] == 1.0  # the constant-epsilon table, bound though compare() does not read it
    assert value["bound"][0]["statement"] == 'q_table_decay, _ = qlearn("Taxi-v3", decay=True)'
    assert (value["bound"][0]["cell"], value["bound"][0]["N"]) == (3, 70_000)


def test_unusual_names_bind_by_the_training_statements() -> None:
    compare = "def compare():\n    return play(table_a), play(table_b)\n"
    module = _module(FUNCTIONS, compare)
    value = _bound(
        module, "table_b = sarsa0('Taxi-v3', decay=True)\ntable_a, pen = qlearn('Taxi-v3', N=500, decay=True)"
    )
    assert module.compare() == (0.0, 10.0)
    assert [(entry["name"], entry["learner"], entry["N"]) for entry in value["bound"]] == [
        ("table_a", "qlearn", 500),
        ("table_b", "sarsa0", 70_000),
    ]


def test_a_module_of_functions_only_binds_by_the_names() -> None:
    module = _module(FUNCTIONS, TEMPLATE_COMPARE)
    value = _bound(module)
    assert module.compare() == (0.0, 10.0)
    assert all(entry["statement"] is None and entry["decay"] is True for entry in value["bound"])


def test_the_last_statement_setting_a_name_wins_as_in_run_all() -> None:
    module = _module(FUNCTIONS, TEMPLATE_COMPARE)
    _bound(
        module,
        "q_table_decay, _ = qlearn('Taxi-v3', decay=True)\nsarsa_table_decay = sarsa0('Taxi-v3', decay=True)",
        "q_table_decay, _ = qlearn('Taxi-v3')",
    )
    assert module.compare() == (1.0, 10.0)


def test_globals_are_read_through_helpers_and_nested_code() -> None:
    module = _module(
        FUNCTIONS,
        "def means():\n    return [play(t) for t in (Q, sarsa_q)]\n\ndef compare():\n    return tuple(means())\n",  # noqa: E501
    )
    names = globals_loaded(module.compare.__code__, vars(module))
    assert names is not None and {"means", "Q", "sarsa_q", "play"} <= set(names)
    _bound(module)
    assert module.compare() == (0.0, 10.0)


@pytest.mark.parametrize(
    ("compare", "cells", "why"),
    [
        (
            "def compare():\n    q, _ = qlearn('Taxi-v3', decay=True)\n    return play(q), play(sarsa_table_decay)\n",  # noqa: E501
            (),
            "compare() calls qlearn() itself, so it trains its own tables",
        ),
        (
            "def compare():\n    return play(globals()['q']), 0.0\n",
            ("q = qlearn('Taxi-v3')[0]",),
            "compare() reads no global that holds or could hold a Q-table",
        ),
        (
            "def compare():\n    return play(q_table_decay), play(q_table_decay)\n",
            (),
            "none of which is the SARSA table",
        ),
        (
            "def compare():\n    return play(tables['q']), play(tables['sarsa'])\n",
            ("tables = {'q': qlearn('Taxi-v3')[0], 'sarsa': sarsa0('Taxi-v3')}",),
            "none of which is the SARSA table",
        ),
        (
            TEMPLATE_COMPARE.replace("play(sarsa_table_decay)", "pen"),
            ("q_table_decay, pen = qlearn('Taxi-v3', decay=True)\nsarsa_table_decay = sarsa0('Taxi-v3')",),
            "compare() reads `pen`, which the training returns besides its table",
        ),
        (
            TEMPLATE_COMPARE.replace("play(sarsa_table_decay)", "episodes"),
            (
                "q_table_decay, _ = qlearn('Taxi-v3')\nsarsa_table_decay = sarsa0('Taxi-v3')\nepisodes = int('3')",  # noqa: E501
            ),
            "compare() reads `episodes`, which cell 2 sets (line 3) and which is neither",
        ),
        (
            TEMPLATE_COMPARE,
            ("q_table_decay, _ = qlearn('Taxi-v3')\nsarsa_table_decay = sarsa('Taxi-v3')",),
            "`sarsa_table_decay` is set by a call of `sarsa` (cell 2, line 2), which your file does not define",  # noqa: E501
        ),
        (TEMPLATE_COMPARE, ("q_table_decay = (",), "cell 2 does not compile, so Run All would stop there"),
    ],
    ids=[
        "trains_itself",
        "reads_globals_dict",
        "one_learner",
        "tables_in_a_dict",
        "penalties",
        "other_global",
        "undefined_learner",
        "broken_cell",
    ],
)
def test_where_binding_cannot_serve_the_cells_run_and_say_why(
    compare: str, cells: tuple[str, ...], why: str
) -> None:
    module = _module(FUNCTIONS, compare)
    try:
        value = _bound(module, *cells, "ran = True")
    except NotebookCellError as error:  # the cell that Run All stops at stops this run too, saying why it ran
        assert f"the cells ran because the grader's tables could not stand in for the training: {why}" in str(
            error
        )
        return
    assert why in value["fallback"]
    assert vars(module)["ran"] is True
    assert "bound" not in value


def test_a_compare_that_is_no_python_function_runs_the_cells() -> None:
    module = _module(FUNCTIONS, "compare = max\n")
    value = _bound(module, "ran = True")
    assert value["fallback"].startswith("compare() is not a plain Python function")
    assert vars(module)["ran"] is True
