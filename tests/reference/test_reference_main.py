"""Tests for `python -m reference` (reference/__main__.py)."""

from __future__ import annotations

import pytest

from reference.__main__ import main

pytestmark = pytest.mark.slow  # runs the reference command end to end


def test_main_job_runs_every_solution_and_prints_the_oracle_table(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--quick", "--seed", "5"]) == 0
    lines = capsys.readouterr().out.splitlines()
    for call in ["random_blackjack(500)", "blackjack(11)", "cartpole()", "car()", "taxi(Q*, episodes=1000)"]:
        assert any(line.strip().startswith(call) for line in lines), call
    assert any(line.endswith("<- best") and line.split()[0] == "13" for line in lines)
    assert any(line.strip().startswith("greedy on Q* (gamma=0.6):") for line in lines)
