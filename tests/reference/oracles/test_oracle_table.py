"""Tests for reference/oracles/table.py and `python -m reference.oracles`."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from reference.oracles.__main__ import main
from reference.oracles.blackjack import random_policy_outcome, threshold_policy_outcome
from reference.oracles.table import build_oracle_table, format_oracle_table, table_as_json_data
from reference.oracles.taxi import random_policy_return


def test_table_collects_the_oracles() -> None:
    table = build_oracle_table()
    assert table.blackjack_random == random_policy_outcome()
    assert table.blackjack_thresholds == tuple(threshold_policy_outcome(n) for n in range(22))
    assert table.best_thresholds == (13,)
    assert table.taxi_random == random_policy_return()
    assert table.taxi_greedy_optimal_q == pytest.approx(table.taxi_optimal)


def test_json_output(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    # The numbers below are regression snapshots of the table's output: the Blackjack ones are derived
    # independently in tests/grader/lab/checks/test_blackjack.py (exact fractions from the rules), Taxi's
    # by simulation in test_taxi_oracle.py, the guessing game's in test_guessing_game_oracle.py.
    assert data["blackjack"]["best_thresholds"] == [13]
    assert [row["n"] for row in data["blackjack"]["threshold_policy"]] == list(range(22))
    assert data["blackjack"]["random_policy"]["win"] == pytest.approx(0.280611314313, abs=1e-12)
    assert data["taxi"]["max_steps"] == 200
    assert data["taxi"]["random_policy"]["mean"] == pytest.approx(-771.09099945, abs=1e-6)
    assert data["taxi"]["optimal_policy"]["mean"] == pytest.approx(7.93, abs=1e-9)
    assert data["taxi"]["greedy_optimal_q"]["gamma"] == 0.6
    assert data["guessing_game"]["guess_count_probabilities"]["8"] == pytest.approx(0.005625, abs=1e-15)
    assert data["guessing_game"]["mean"] == pytest.approx(5.805625, abs=1e-12)


def test_text_table_marks_the_best_threshold() -> None:
    text = format_oracle_table(build_oracle_table())  # the printed figures: regression snapshots
    assert "    13  0.4180 0.0818 0.5003  -0.0823  <- best" in text.splitlines()
    assert text.count("<- best") == 1
    assert "  random policy:            -771.0910 (101.8264)" in text.splitlines()
    assert "  mean 5.805625 (std 1.3263)" in text.splitlines()


def test_json_data_is_plain() -> None:
    json.dumps(table_as_json_data(build_oracle_table()), allow_nan=False)


def test_module_runs_as_a_command() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "reference.oracles", "--json"],
        capture_output=True,
        text=True,
        check=True,
        timeout=60,
    )
    assert json.loads(result.stdout)["blackjack"]["best_thresholds"] == [13]
