"""Detection reads which edition a submission was written for, statically and within bounds."""

import json
import tomllib
from pathlib import Path

import pytest

from grader.lab.editions import EDITIONS
from grader.lab.editions.detection import MAX_NOTEBOOK_BYTES, detect_edition, edition_note

SUBMISSIONS = Path(__file__).resolve().parents[4] / "submissions"


@pytest.mark.parametrize("name", list(EDITIONS))
def test_each_template_is_detected_as_its_edition(name: str) -> None:
    edition = EDITIONS[name]
    assert detect_edition(edition.template).edition is edition


def test_the_rl1_notebook_template_is_detected_as_rl1() -> None:
    assert detect_edition(SUBMISSIONS / "templates" / "rl1.ipynb").edition is EDITIONS["rl1"]


@pytest.mark.parametrize("name", list(EDITIONS))
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


RL2_SAMPLES = tomllib.loads((SUBMISSIONS / "rl2" / "verdicts.toml").read_text(encoding="utf-8"))["sample"]


@pytest.mark.parametrize("sample", RL2_SAMPLES, ids=[sample["file"] for sample in RL2_SAMPLES])
def test_every_second_lab_sample_is_detected_as_the_lab_and_edition_it_is_graded_in(sample: dict) -> None:
    detection = detect_edition(SUBMISSIONS / sample["file"])
    assert (detection.edition.lab, detection.edition.name) == (sample["lab"], sample["edition"])
    assert detection.shown and detection.lab_shown


def test_every_file_of_the_second_labs_samples_shows_that_lab() -> None:
    files = sorted((SUBMISSIONS / "rl2").rglob("*.py"))
    assert len(files) >= 20
    assert {path.name: detect_edition(path).edition.lab for path in files} == {
        path.name: "rl2" for path in files
    }


@pytest.mark.parametrize(
    ("name", "source", "edition", "reason", "shown"),
    [
        (
            "policy_iteration.py",
            "def model_comparison(episodes=1000):\n    pass\n",
            "v2024",
            "it defines model_comparison(episodes), which only the 2024 edition",
            True,
        ),
        (
            "policy_iteration.py",
            "import model_free_RL\ndef value_iteration(P, nS, nA):\n    pass\n",
            "v2024",
            "it imports model_free_RL",
            True,
        ),
        (
            "policy_iteration.py",
            "def frozenlake(basic_case=True, M=1000):\n    pass\n",
            "v2018",
            "it defines frozenlake(basic_case, M), the 2018 name",
            True,
        ),
        (
            "policy_iteration.py",
            "def run_simulation(env, policy, render=True, beta=1.0):\n    pass\n",
            "v2019",
            "takes a render flag, as the 2019-2022 editions",
            True,
        ),
        (
            "policy_iteration.py",
            "def iter_policy_eval(P, nS, nA, policy):\n    pass\n",
            "v2026",
            "it defines iter_policy_eval (the names since 2024) and no model_comparison",
            True,
        ),
        (
            "policy_function_iteration.py",
            "def value_iteration(P, nS, nA):\n    pass\n",
            "v2026",
            "it is named policy_function_iteration.py, as the 2026 template",
            True,
        ),
        (
            "policy_iteration.py",
            "import gymnasium as gym\ndef extract_policy(P, nS, nA, v):\n    pass\n",
            "v2023",
            "it defines extract_policy (the 2018-2023 names) and imports gymnasium",
            True,
        ),
        (
            "policy_iteration.py",
            "import gym\ndef compute_policy_v(P, nS, nA, policy):\n    pass\n",
            "v2019",
            "it defines compute_policy_v (the 2018-2023 names) and imports gym",
            True,
        ),
        (
            "mine.py",
            "def value_iteration(P, nS, nA):\n    pass\n",
            "v2026",
            "it defines value_iteration, so it was written for the Policy Function Iteration lab",
            False,
        ),
        (
            "policy_iteration.py",
            "",
            "v2026",
            "it is named policy_iteration.py, so it was written for the Policy Function Iteration lab",
            False,
        ),
        # Hostile: a file defining both labs' functions is the second lab's (no first-lab name)
        (
            "opengym.py",
            "import gym\ndef blackjack(n=11):\n    pass\ndef value_iteration(P, nS, nA):\n    pass\n",
            "v2026",
            "it defines value_iteration",
            False,
        ),
    ],
    ids=[
        "model_comparison",
        "model_free_RL",
        "frozenlake",
        "render",
        "2024-names",
        "2026-file-name",
        "gymnasium-old-names",
        "gym-old-names",
        "lab-only",
        "empty-named",
        "both-labs",
    ],
)
def test_the_second_labs_rules_and_their_reasons(
    tmp_path: Path, name: str, source: str, edition: str, reason: str, shown: bool
) -> None:
    path = tmp_path / name
    path.write_text(source, encoding="utf-8")
    detection = detect_edition(path)
    assert (detection.edition.lab, detection.edition.name) == ("rl2", edition)
    assert reason in detection.reason
    assert (detection.shown, detection.lab_shown) == (shown, True)


@pytest.mark.parametrize(
    ("name", "source", "lab_shown"),
    [
        ("opengym.py", "", False),
        ("notes.py", "x = 1\n", False),
        ("opengym.py", "def blackjack(n=11):\n    pass\n", True),
        # Hostile: the second lab's file name does not outweigh the first lab's functions.
        ("policy_iteration.py", "def blackjack(n=11):\n    pass\n", True),
    ],
    ids=[
        "empty",
        "nothing-of-a-lab",
        "a-first-lab-function",
        "first-lab-function-under-the-second-labs-name",
    ],
)
def test_a_file_showing_no_lab_is_told_apart_from_one_showing_the_first_lab(
    tmp_path: Path, name: str, source: str, lab_shown: bool
) -> None:
    path = tmp_path / name
    path.write_text(source, encoding="utf-8")
    detection = detect_edition(path)
    assert (detection.edition.name, detection.shown, detection.lab_shown) == ("classic", False, lab_shown)


def test_a_file_of_another_lab_is_told_so_whatever_it_shows_of_an_edition() -> None:
    second = detect_edition(SUBMISSIONS / "rl2" / "honest_v2024.py")
    note = edition_note(EDITIONS["classic"], second)
    assert note is not None and note.startswith(
        "This file looks written for the lab rl2 (Policy Function Iteration / Reinforcement Learning 2): it "
        "defines model_comparison(episodes), which only the 2024 edition asks for. Your assignment is the lab "  # noqa: E501
        "opengym (OpenGym AI / Reinforcement Learning 1), edition classic"
    )
    first = detect_edition(SUBMISSIONS / "classic_complete.py")
    assert "written for the lab opengym" in (edition_note(EDITIONS["v2026"], first) or "")
    assert (
        edition_note(EDITIONS["v2019"], detect_edition(SUBMISSIONS / "rl2" / "honest_v2023.py")) is not None
    )
    assert edition_note(EDITIONS["v2024"], second) is None
