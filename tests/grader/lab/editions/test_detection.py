"""Detection reads which edition a submission was written for, statically and within bounds."""

import json
from pathlib import Path

import pytest

from grader.lab.editions import EDITIONS
from grader.lab.editions.detection import MAX_NOTEBOOK_BYTES, detect_edition

SUBMISSIONS = Path(__file__).resolve().parents[4] / "submissions"
OPENGYM = [name for name, edition in EDITIONS.items() if edition.lab == "opengym"]
"""The editions detection tells apart today (the second lab's detection is the labs branch's)."""


@pytest.mark.parametrize("name", OPENGYM)
def test_each_template_is_detected_as_its_edition(name: str) -> None:
    edition = EDITIONS[name]
    assert detect_edition(edition.template).edition is edition


def test_the_rl1_notebook_template_is_detected_as_rl1() -> None:
    assert detect_edition(SUBMISSIONS / "templates" / "rl1.ipynb").edition is EDITIONS["rl1"]


@pytest.mark.parametrize("name", OPENGYM)
def test_each_reference_is_detected_as_its_edition_or_an_edition_grading_the_same(name: str) -> None:
    edition = EDITIONS[name]
    assert detect_edition(edition.reference).edition.registry is edition.registry


@pytest.mark.parametrize(
    ("source", "edition", "reason", "shown"),
    [
        (
            "def epsilon_decay(i, n, a=1.0, b=1e-6):\n    pass\n",
            "rl1",
            "it defines epsilon_decay(i, n, a, b)",
            True,
        ),
        ("def taxi(q, q2):\n    pass\n", "rl1", "its taxi(q, q2) takes two tables", True),
        ("def taxi(q, q2=None):\n    pass\n", "classic", "it shows no edition: it imports no gym", False),
        ("def cartpole(render=False):\n    pass\n", "volume2", "its cartpole(render=...) take", True),
        ("import gymnasium as gym\n", "volume2", "imports gymnasium", True),
        ("import gym\nobs, r, te, tr, info = env.step(0)\n", "gym026", "five values", True),
        ("import gym\nobs, info = env.reset()\n", "gym026", "five values", True),
        ("import gym\nobs, r, done, info = env.step(0)\n", "classic", "no mark of a later edition", True),
        ("def cartpole(:\n", "classic", "could not be read as Python, so it shows no edition", False),
        ("", "classic", "it shows no edition", False),
        ("def random_blackjack(n):\n    return 0.5\n", "classic", "it shows no edition", False),
    ],
    ids=[
        "epsilon_decay",
        "two_table_taxi",
        "optional_second_table",
        "render",
        "gymnasium",
        "step5",
        "reset2",
        "classic_step",
        "syntax_error",
        "empty",
        "one_shared_function",
    ],
)
def test_rules_and_their_reasons(tmp_path: Path, source: str, edition: str, reason: str, shown: bool) -> None:
    path = tmp_path / "opengym.py"
    path.write_text(source, encoding="utf-8")
    detection = detect_edition(path)
    assert detection.edition.name == edition
    assert reason in detection.reason
    assert detection.shown is shown


def test_a_notebook_is_read_cell_by_cell_skipping_magics_and_broken_cells(tmp_path: Path) -> None:
    cells = [
        {"cell_type": "code", "source": ["%matplotlib inline\n", "import gymnasium as gym\n"]},
        {"cell_type": "code", "source": "def broken(:\n"},
        {"cell_type": "markdown", "source": "def epsilon_decay(): pass"},
        {"cell_type": "code", "source": ["def sarsa0(env, alpha=0.1):\n", "    pass\n"]},
    ]
    path = tmp_path / "gymnasium.ipynb"
    path.write_text(json.dumps({"cells": cells, "nbformat": 4}), encoding="utf-8")
    detection = detect_edition(path)
    assert detection.edition.name == "rl1"
    assert "sarsa0(env, alpha)" in detection.reason
    assert "epsilon_decay" not in detection.reason  # a markdown cell is not code


@pytest.mark.parametrize(
    "data",
    [
        b"[" * 200_000 + b"]" * 200_000,  # nesting that would overflow a recursive parser
        b'{"cells": 3}',
        b"\xff\xfe not json",
        b" " * (MAX_NOTEBOOK_BYTES + 1),
    ],
    ids=["deep_json", "cells_not_a_list", "not_utf8", "too_large"],
)
def test_a_hostile_notebook_shows_no_mark_and_never_raises(tmp_path: Path, data: bytes) -> None:
    path = tmp_path / "gymnasium.ipynb"
    path.write_bytes(data)
    detection = detect_edition(path)
    assert detection.edition.name == "classic"
    assert "could not be read as Python" in detection.reason


def test_deeply_nested_python_is_no_crash(tmp_path: Path) -> None:
    path = tmp_path / "opengym.py"
    path.write_text(
        "x = " + "(" * 100_000 + ")" * 100_000 + "\ndef sarsa0(env):\n    pass\n", encoding="utf-8"
    )
    assert detect_edition(path).edition.name == "classic"  # the file does not parse: no mark is read
