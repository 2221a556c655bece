"""bench/lti_outbox.py at a tiny size: its population and rounds still fit the models and the publisher
(slow: a migrated database and an RSA key, about a second)."""

from __future__ import annotations

import argparse
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest

BENCH = Path(__file__).resolve().parents[2] / "bench"


@pytest.fixture
def bench(monkeypatch: pytest.MonkeyPatch) -> ModuleType:
    """The bench script as a module (it imports its neighbour ``results_section`` and puts the repository on
    ``sys.path``: both undone after the test)."""
    monkeypatch.setattr(sys, "path", [str(BENCH), *sys.path])
    spec = importlib.util.spec_from_file_location("lti_outbox_bench", BENCH / "lti_outbox.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, spec.name, module)
    spec.loader.exec_module(module)
    return module


@pytest.mark.slow
def test_the_bench_makes_a_row_per_learner_and_its_idle_round_changes_none(
    bench: ModuleType, tmp_path: Path
) -> None:
    figures = bench.measure(tmp_path, students=3, submissions=2, rounds=1)
    assert figures.first_rows == 3
    assert len(figures.idle) == 1
    args = argparse.Namespace(students=3, submissions=2, rounds=1)
    text = bench.section(args, figures)
    assert text.startswith(bench.HEADING + "\n")
    assert "| first round (3 rows made) |" in text
