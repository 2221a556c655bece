"""compare() with the grader's tables bound (issue 44) against the plain Run All of the same notebook.

A/B in one run, on the same machine, one after the other (the shared machine's load is printed with each,
so record the ratios, not the seconds):

- **bound**: `compare` alone (`--only compare`), edition rl1's default configuration (`bind_tables = true`),
  one worker: the problem's wall time (a sandbox child, the grader's tables bound to the globals compare()
  reads, compare() recorded, its 2 000 episodes replayed and judged);
- **check**: the whole `gymgrade check` of the notebook (every problem, the default workers), in a
  subprocess, as a student runs it;
- **plain**: the notebook's code cells in one plain Python process (`bench/compare_cost.py`'s Run All);
- **bounded training** (the alternative the issue weighed): the notebook's own `qlearn` and `sarsa0`
  (decay=True) trained on N episodes in this process: their seconds, and the share of starts from which
  greedy play on the table does not end within Taxi's 200 steps (a compare() looping `while not done` on
  `terminated` alone never ends there, where the lab's N = 70 000 tables end from every start).

The default notebook is `submissions/editions/rl1_template_honest.ipynb` (the course's template with the
lab's own cells at N = 70 000). The plain run takes about 10 minutes idle; run it in the background:

    nohup scripts/run python3 bench/compare_bound.py > compare_bound.log 2>&1 &
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
import types
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from compare_cost import (  # noqa: E402
    NOTEBOOK,
    PLAIN_RUNNER,
    _children_cpu,
    code_cells,
    graded_run,
    plain_run,
)

from reference.oracles.taxi import TIME_LIMIT, taxi_model  # noqa: E402

BOUNDED_EPISODES = (2_000, 7_000)


def capped_plain_run(notebook: Path, directory: Path, limit: float) -> dict[str, float | bool]:
    """Run All in one plain process, stopped after `limit` seconds of wall: its wall and CPU so far.

    On a loaded machine the plain process may get a tenth of a core; stopped unfinished, its CPU so far is a
    lower bound of the whole Run All's, so the ratio it gives is an upper bound.
    """
    cells = directory / "cells.json"
    cells.write_text(json.dumps(code_cells(notebook)), encoding="utf-8")
    runner = directory / "plain_runner.py"
    runner.write_text(PLAIN_RUNNER, encoding="utf-8")
    environment = {**os.environ, "MPLBACKEND": "Agg", "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy"}
    cpu, started = _children_cpu(), time.perf_counter()
    process = subprocess.Popen(
        [sys.executable, str(runner), str(cells)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=environment,
        cwd=directory,
    )
    try:
        process.wait(timeout=limit)
        finished = process.returncode == 0
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
        finished = False
    return {"wall": time.perf_counter() - started, "cpu": _children_cpu() - cpu, "finished": finished}


def whole_check(notebook: Path) -> dict[str, object]:
    """`gymgrade check NOTEBOOK` in a subprocess: its wall time and exit status."""
    started = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "grader", "check", str(notebook), "--edition", "rl1"],
        capture_output=True,
        text=True,
        check=False,
    )
    wall = time.perf_counter() - started
    tail = [line for line in done.stdout.splitlines() if "score" in line.lower()][-1:]
    return {"wall": wall, "exit": done.returncode, "score": tail[0].strip() if tail else done.stdout[-300:]}


def _unended_share(table: np.ndarray) -> float:
    model = taxi_model()
    actions = np.argmax(table, axis=1)
    starts = np.flatnonzero(model.initial_distribution > 0)
    unended = 0
    for start in starts:
        state = int(start)
        for _ in range(TIME_LIMIT):
            action = int(actions[state])
            if model.terminates[state, action]:
                break
            state = int(model.next_state[state, action])
        else:
            unended += 1
    return unended / len(starts)


def bounded_training(notebook: Path) -> list[str]:
    """The notebook's own learners at a few bounded N: seconds and unended share per table."""
    import gymnasium

    spec = gymnasium.spec("Taxi-v4")
    if "Taxi-v3" not in gymnasium.registry:
        gymnasium.register("Taxi-v3", entry_point=spec.entry_point, max_episode_steps=spec.max_episode_steps)
    namespace: dict[str, object] = {"__name__": "bounded"}
    module = types.ModuleType("bounded")
    for source in code_cells(notebook):
        if source.lstrip().startswith(("import", "from", "def")):  # the imports and definitions, no demo
            exec(compile(source, "<cell>", "exec"), vars(module))
    namespace.update(vars(module))
    lines = []
    for episodes in BOUNDED_EPISODES:
        for learner in ("qlearn", "sarsa0"):
            started = time.perf_counter()
            value = namespace[learner]("Taxi-v3", N=episodes, decay=True)  # type: ignore[operator]
            seconds = time.perf_counter() - started
            table = value[0] if isinstance(value, tuple) else value
            lines.append(
                f"  {learner}(decay=True, N={episodes}): {seconds:.1f} s; greedy play does not end from "
                f"{100 * _unended_share(np.asarray(table)):.1f}% of the starts"
            )
    return lines


def main() -> None:
    """Measure all four, print each and the ratios."""
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--notebook", type=Path, default=NOTEBOOK)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--skip-plain", action="store_true", help="leave out the 10-minute plain Run All")
    parser.add_argument("--skip-bounded", action="store_true", help="leave out the bounded training")
    parser.add_argument("--only-bounded", action="store_true", help="only the bounded training")
    parser.add_argument(
        "--plain-limit",
        type=float,
        default=None,
        help="stop the plain Run All after this many s of wall",
    )
    arguments = parser.parse_args()
    notebook = arguments.notebook
    if arguments.only_bounded:
        for line in bounded_training(notebook):
            print(line, flush=True)
        return
    print(f"notebook {notebook.name}; load average before: {os.getloadavg()}", flush=True)
    bound = graded_run(notebook, arguments.seed)
    print(
        f"bound compare (rl1 default configuration, 1 worker): {bound['status']}, problem wall "
        f"{bound['problem_wall']:.1f} s (student {bound['student_seconds']:.1f} s), file wall "
        f"{bound['file_wall']:.1f} s; load {os.getloadavg()}",
        flush=True,
    )
    print(f"  feedback: {bound['feedback']}", flush=True)
    check = whole_check(notebook)
    print(
        f"whole gymgrade check: {check['wall']:.1f} s wall, exit {check['exit']}, {check['score']}; "
        f"load {os.getloadavg()}",
        flush=True,
    )
    if not arguments.skip_bounded:
        print("bounded training of the notebook's own learners:", flush=True)
        for line in bounded_training(notebook):
            print(line, flush=True)
    if arguments.skip_plain:
        return
    with tempfile.TemporaryDirectory() as temporary:
        if arguments.plain_limit is None:
            plain: dict[str, float | bool] = {**plain_run(notebook, Path(temporary)), "finished": True}
        else:
            plain = capped_plain_run(notebook, Path(temporary), arguments.plain_limit)
    print(
        f"plain Run All: {'finished' if plain['finished'] else 'STOPPED unfinished'} after "
        f"{plain['wall']:.1f} s wall, {plain['cpu']:.1f} s CPU; load {os.getloadavg()}",
        flush=True,
    )
    if not plain["finished"]:
        bound_over_cpu = float(bound["problem_wall"]) / float(plain["cpu"])  # type: ignore[arg-type]
        print(f"ratio bound compare problem wall / plain Run All CPU so far: below {bound_over_cpu:.3f}")
        return
    ratio = float(bound["problem_wall"]) / float(plain["wall"])  # type: ignore[arg-type]
    print(
        f"ratio bound compare problem / plain Run All: {ratio:.3f} (wall); whole check {check['wall']:.1f} s"
    )


if __name__ == "__main__":
    main()
