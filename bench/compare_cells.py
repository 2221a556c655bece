"""compare() and the notebook's cells (issue 23): calibration in-process, and the cost of running the cells.

1. Calibration, in-process with the real check (`grader.simulated_students.compare` students run by
   `grader.simulated_students.simulation`, the cells call simulated with the grader's two taxi tables as the
   notebook's tables): the honest compare() (and one playing the SARSA table first) regraded `--regrades`
   times, each typical mistake `--mistake-regrades` times.
2. The cost of grading a complete current-edition notebook in the real sandbox, once with rl1's default
   configuration (compare() not gradable in isolation: skipped, no cells run) and once with
   `run_cells = true`. The notebook is built from the rl1 reference (`submissions/editions/rl1_complete.py`):
   one cell per top-level statement, then a training cell (`qlearn(..., N=--q-episodes)` and
   `sarsa0(..., N=--sarsa-episodes)`, alpha 0.5, gamma 0.9: the lab's N = 70 000 takes minutes per learner)
   and a `print(compare())` cell.

    python bench/compare_cells.py              # 200 honest regrades, 50 per mistake, both gradings
    python bench/compare_cells.py --regrades 20 --no-sandbox
"""

from __future__ import annotations

import argparse
import ast
import sys
import tempfile
import time
import tomllib
from collections import Counter
from pathlib import Path
from typing import Any

import nbformat
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from grader.grading.grade import grade_files
from grader.grading.plan import GradingPlan
from grader.lab.assignment import load_config
from grader.lab.checks.compare import CompareConfig
from grader.lab.editions.rl1 import RL1
from grader.report import Report
from grader.sandbox import IsolationPolicy
from grader.sandbox.child.cells import RUN_CELLS
from grader.simulated_students import compare as students
from grader.simulated_students.simulation import simulate_calls

REFERENCE = Path(__file__).resolve().parents[1] / "submissions" / "editions" / "rl1_complete.py"


def _statuses(function: Any, regrades: int) -> Counter[str]:
    problem = RL1.registry.problem("compare")
    settings = load_config(RL1.default_config).problems["compare"]
    assert isinstance(settings, CompareConfig)
    settings = CompareConfig.model_validate({**settings.model_dump(), "run_cells": True}).for_problem(
        "compare", problem.games
    )
    calls = problem.check.plan(settings, {}, 0)
    found: Counter[str] = Counter()
    for seed in range(regrades):
        records = simulate_calls(calls, {RUN_CELLS: students.cells, "compare": function}, seed)
        found[problem.check.judge(settings, records).status] += 1
    return found


def calibrate(regrades: int, mistake_regrades: int) -> None:
    print(f"compare() calibration: {regrades} regrades per honest student, {mistake_regrades} per mistake")
    for name, function in (("honest", students.honest), ("sarsa_first", students.sarsa_first)):
        started = time.perf_counter()
        print(f"  {name}: {dict(_statuses(function, regrades))} ({time.perf_counter() - started:.0f} s)")
    for name, (function, _) in students.MISTAKES.items():
        print(f"  {name}: {dict(_statuses(function, mistake_regrades))}")


def complete_notebook(q_episodes: int, sarsa_episodes: int) -> bytes:
    """The rl1 reference as a notebook: a cell per top-level statement, training cells, compare()."""
    source = REFERENCE.read_text(encoding="utf-8")
    lines = source.splitlines()
    cells = [new_markdown_cell("# Reinforcement Learning 1: Gymnasium\nC. Student")]
    for statement in ast.parse(source).body:
        if isinstance(statement, ast.If):  # the __main__ demo block: the notebook's own cells replace it
            continue
        first = min([statement.lineno, *(d.lineno for d in getattr(statement, "decorator_list", []))])
        cells.append(new_code_cell("\n".join(lines[first - 1 : statement.end_lineno])))
    training = (
        'env = gym.make("Taxi-v3")\n'
        f"q_table_decay, _ = qlearn(env, alpha=0.5, gamma=0.9, N={q_episodes})\n"
        'env = gym.make("Taxi-v3")\n'
        f"sarsa_table_decay, _ = sarsa0(env, alpha=0.5, gamma=0.9, N={sarsa_episodes})"
    )
    cells += [new_code_cell(training), new_code_cell("print(compare())")]
    return nbformat.writes(new_notebook(cells=cells)).encode()


def _config(directory: Path, run_cells: bool) -> Path:
    text = RL1.default_config.read_text(encoding="utf-8")
    if run_cells:
        text = text.replace("run_cells = false", "run_cells = true")
    path = directory / f"rl1_cells_{run_cells}.toml"
    path.write_text(text, encoding="utf-8")
    assert tomllib.loads(text)["problems"]["compare"]["run_cells"] is run_cells
    return path


def _grade(notebook: Path, config: Path, workers: int) -> tuple[float, Report]:
    plan = GradingPlan.load(config, None)
    started = time.perf_counter()
    (report,) = grade_files([notebook], plan, seed=1, workers=workers, policy=IsolationPolicy.ALLOW_FALLBACK)
    return time.perf_counter() - started, report


def cost(q_episodes: int, sarsa_episodes: int, workers: int) -> None:
    print(
        f"complete rl1 notebook (training cells: qlearn N={q_episodes}, sarsa0 N={sarsa_episodes}), "
        f"all rl1 problems, {workers} workers"
    )
    with tempfile.TemporaryDirectory() as temporary:
        directory = Path(temporary)
        notebook = directory / "gymnasium.ipynb"
        notebook.write_bytes(complete_notebook(q_episodes, sarsa_episodes))
        for run_cells in (False, True):
            wall, report = _grade(notebook, _config(directory, run_cells), workers)
            compare = next(result for result in report.problems if result.id == "compare")
            others = sum(r.timings.wall_seconds for r in report.problems if r.id != "compare")
            student = compare.timings.student_seconds if compare.timings else float("nan")
            print(
                f"  run_cells={run_cells}: {wall:.1f} s wall for the file; "
                f"compare {compare.status} {compare.score}/{compare.max_score} in "
                f"{compare.timings.wall_seconds:.1f} s (in the cells and compare() {student:.1f} s); "
                f"the other {len(report.problems) - 1} problems {others:.1f} s summed; "
                + ", ".join(f"{r.id} {r.status}" for r in report.problems)
            )


def main() -> None:
    """Run the calibration and the cost measurement."""
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--regrades", type=int, default=200)
    parser.add_argument("--mistake-regrades", type=int, default=50)
    parser.add_argument("--q-episodes", type=int, default=2000)
    parser.add_argument("--sarsa-episodes", type=int, default=500)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--no-sandbox", action="store_true", help="calibration only")
    parser.add_argument("--no-calibration", action="store_true", help="the sandbox cost only")
    arguments = parser.parse_args()
    if not arguments.no_calibration:
        calibrate(arguments.regrades, arguments.mistake_regrades)
    if not arguments.no_sandbox:
        cost(arguments.q_episodes, arguments.sarsa_episodes, arguments.workers)


if __name__ == "__main__":
    main()
