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

    nohup scripts/run python3 bench/compare_bound.py --skip-bounded --write > compare_bound.log 2>&1 &

`--plain-limit S` stops the Run All after S seconds of wall (a loaded machine may give it a tenth of a
core): the section then says how many cells it finished and bounds the ratio by its CPU so far.
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
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from compare_cost import (  # noqa: E402
    NOTEBOOK,
    _children_cpu,
    code_cells,
    graded_run,
)
from results_section import replace_section  # noqa: E402

from reference.oracles.taxi import TIME_LIMIT, taxi_model  # noqa: E402

BOUNDED_EPISODES = (2_000, 7_000)
HEADING = "## compare() with bound tables (issue 44): its cost against the plain Run All"
PROGRESS_RUNNER = """
import json, sys, time
import gymnasium
spec = gymnasium.spec("Taxi-v4")
gymnasium.register("Taxi-v3", entry_point=spec.entry_point, max_episode_steps=spec.max_episode_steps,
                   reward_threshold=spec.reward_threshold)
cells = json.load(open(sys.argv[1], encoding="utf-8"))
namespace = {"__name__": "__main__"}
progress = open(sys.argv[2], "a", encoding="utf-8")
for index, source in enumerate(cells):
    started = time.perf_counter()
    exec(compile(source, "<cell>", "exec"), namespace)
    progress.write(json.dumps({"cell": index, "seconds": time.perf_counter() - started}) + "\\n")
    progress.flush()
"""
"""The plain Run All (`compare_cost.PLAIN_RUNNER`'s), writing each finished cell's seconds as it goes, so a
run stopped unfinished says how far it got."""


def capped_plain_run(notebook: Path, directory: Path, limit: float) -> dict[str, float | bool]:
    """Run All in one plain process, stopped after `limit` seconds of wall: its wall, CPU, cells done so far.

    On a loaded machine the plain process may get a tenth of a core; stopped unfinished, its CPU so far is a
    lower bound of the whole Run All's, so the ratio it gives is an upper bound.
    """
    cells = directory / "cells.json"
    sources = code_cells(notebook)
    cells.write_text(json.dumps(sources), encoding="utf-8")
    runner = directory / "plain_runner.py"
    runner.write_text(PROGRESS_RUNNER, encoding="utf-8")
    progress = directory / "progress.jsonl"
    environment = {**os.environ, "MPLBACKEND": "Agg", "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy"}
    cpu, started = _children_cpu(), time.perf_counter()
    process = subprocess.Popen(
        [sys.executable, str(runner), str(cells), str(progress)],
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
    wall = time.perf_counter() - started
    done = [json.loads(line) for line in progress.read_text(encoding="utf-8").splitlines() if line.strip()]
    return {
        "wall": wall,
        "cpu": _children_cpu() - cpu,
        "finished": finished and len(done) == len(sources),
        "cells_done": len(done),
        "cells": len(sources),
        "exit": process.returncode,
    }


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


def section(
    command: str,
    notebook: Path,
    bound: dict[str, object],
    check: dict[str, object],
    plain: dict[str, float | bool] | None,
    loads: dict[str, tuple[float, float, float]],
    span: str,
) -> str:
    """The section bench/RESULTS.md files under `## compare(): cost against the plain Run All`."""

    def load(key: str) -> str:
        return f"{loads[key][0]:.1f}" if key in loads else "-"

    compare_wall = float(bound["problem_wall"])  # type: ignore[arg-type]
    lines = [
        HEADING,
        f"`{command}`, {span}, 1-minute load average at each step as given (the machine is shared: read "
        f"the CPU figures and the ratios). `{notebook.relative_to(ROOT)}` (the course's template, the lab's "
        "cells at N = 70 000): its compare problem alone at rl1's default (`bind_tables = true`, one "
        "worker), its whole `gymgrade check` (8 problems, default workers), its plain Run All (every code "
        "cell `exec`ed in order in one plain Python process, as Run All without Jupyter's kernel; "
        "matplotlib on Agg, pygame on SDL's dummy driver).",
        "",
        "| what | measured | load | target |",
        "|---|---|---|---|",
        f"| compare problem, tables bound (no cell run) | **{compare_wall:.1f} s** wall (compare() itself "
        f"{float(bound['student_seconds']):.1f} s), {bound['status']} | {load('bound')} | - |",  # type: ignore[arg-type]
        f"| whole `gymgrade check` of the notebook | **{float(check['wall']):.1f} s** wall, {check['score']} "  # type: ignore[arg-type]
        f"| {load('check')} | <= 60 s: {'met' if float(check['wall']) <= 60 else 'NOT met'} |",  # type: ignore[arg-type]
    ]
    if plain is None:
        lines.append("| plain Run All | not run (`--skip-plain`) | - | - |")
    else:
        cpu, wall = float(plain["cpu"]), float(plain["wall"])
        if plain["finished"]:
            lines += [
                f"| plain Run All of the same notebook | **{wall:.1f} s** wall, {cpu:.1f} s CPU "
                f"| {load('plain')} | - |",
                f"| ratio compare problem / plain Run All | **{compare_wall / wall:.4f}** (wall / wall); "
                f"{compare_wall / cpu:.4f} (compare's wall / the Run All's CPU, which load cannot stretch) "
                f"| - | <= 0.05x: {'met' if compare_wall / cpu <= 0.05 else 'NOT met'} |",
            ]
        else:
            lines += [
                f"| plain Run All of the same notebook | stopped unfinished after {wall:.0f} s wall: "
                f"{plain.get('cells_done', '?')} of {plain.get('cells', '?')} code cells done, "
                f"{cpu:.1f} s CPU | {load('plain')} | - |",
                f"| ratio compare problem / plain Run All | **below {compare_wall / cpu:.4f}** (compare's "
                "wall / the Run All's CPU so far, a lower bound of its whole CPU) | - | "
                f"<= 0.05x: {'met' if compare_wall / cpu <= 0.05 else 'not shown'} |",
            ]
    lines += ["", f"compare()'s feedback: {str(bound['feedback'])[:200]}...", ""]
    return "\n".join(lines)


def main() -> None:
    """Measure all four, print each and the ratios; with --write, record the section."""
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
    parser.add_argument("--write", action="store_true", help="replace this bench's section of RESULTS.md")
    arguments = parser.parse_args()
    notebook = arguments.notebook.resolve()
    if arguments.only_bounded:
        for line in bounded_training(notebook):
            print(line, flush=True)
        return
    began = datetime.now(UTC)
    loads: dict[str, tuple[float, float, float]] = {}
    print(f"notebook {notebook.name}; load average before: {os.getloadavg()}", flush=True)
    bound = graded_run(notebook, arguments.seed)
    loads["bound"] = os.getloadavg()
    print(
        f"bound compare (rl1 default configuration, 1 worker): {bound['status']}, problem wall "
        f"{bound['problem_wall']:.1f} s (student {bound['student_seconds']:.1f} s), file wall "
        f"{bound['file_wall']:.1f} s; load {loads['bound']}",
        flush=True,
    )
    print(f"  feedback: {bound['feedback']}", flush=True)
    check = whole_check(notebook)
    loads["check"] = os.getloadavg()
    print(
        f"whole gymgrade check: {check['wall']:.1f} s wall, exit {check['exit']}, {check['score']}; "
        f"load {loads['check']}",
        flush=True,
    )
    if not arguments.skip_bounded:
        print("bounded training of the notebook's own learners:", flush=True)
        for line in bounded_training(notebook):
            print(line, flush=True)
    plain: dict[str, float | bool] | None = None
    if not arguments.skip_plain:
        with tempfile.TemporaryDirectory() as temporary:
            limit = arguments.plain_limit if arguments.plain_limit is not None else float("inf")
            plain = capped_plain_run(notebook, Path(temporary), limit)
        loads["plain"] = os.getloadavg()
        print(
            f"plain Run All: {'finished' if plain['finished'] else 'STOPPED unfinished'} after "
            f"{plain['wall']:.1f} s wall, {plain['cpu']:.1f} s CPU, {plain['cells_done']} of "
            f"{plain['cells']} cells; load {loads['plain']}",
            flush=True,
        )
    ended = datetime.now(UTC)
    span = f"{began:%Y-%m-%d %H:%M}-{ended:%H:%M} UTC"
    command = " ".join(["python", "bench/compare_bound.py", *sys.argv[1:]])
    text = section(command, notebook, bound, check, plain, loads, span)
    print(text)
    if arguments.write:
        replace_section(HEADING, text)


if __name__ == "__main__":
    main()
