"""What grading compare() costs by default (issue 31): its problem's wall time against a plain Run All.

A/B in one run, on the same machine, one after the other:

- **plain**: the notebook's code cells, in order, in one plain Python process (Run All without Jupyter): no
  sandbox, no recording, gymnasium's own Taxi (`Taxi-v3` registered as gymnasium's Taxi-v4 spec under the
  lab's id, 200-step limit), matplotlib on Agg and pygame on SDL's dummy video driver (the render cells draw
  off screen at the render_fps gymnasium paces them to).
- **graded**: `compare` alone (`--only compare`) with edition rl1's default configuration
  (`grader/lab/editions/rl1.toml`: `run_cells = true`), one worker: the problem's wall time (a sandbox child,
  the notebook's cells run in it, then compare() recorded, its 2 000 episodes replayed and judged).

The ratio graded / plain, in wall time, is the figure `bench/RESULTS.md` records (target at most 1.0); the
plain run's CPU time is printed too (on a machine shared with other work, wall time stretches and CPU time
does not). The graded side's CPU is not: its sandbox child runs under bubblewrap in a cgroup of its own and
its xdist worker is killed at the end of the session, so neither reaches this process's
`RUSAGE_CHILDREN`. The default notebook
is `submissions/editions/rl1_template_honest.ipynb`, written from the course's template with the lab's own
cells (`qlearn("Taxi-v3")`, `qlearn("Taxi-v3", decay=True)`, `sarsa0("Taxi-v3", decay=True)` at N = 70 000,
the demos of problems 1-4, `print(compare())`). The plain run takes about 10 minutes; run it in the
background. `--episodes N` trains with N episodes instead of the lab's 70 000 (the learners' default `N`
in the notebook rewritten, both sides alike):

    nohup scripts/run python3 bench/compare_cost.py > compare_cost.log 2>&1 &
    scripts/run python3 bench/compare_cost.py --episodes 7000
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from grader.grading.grade import grade_files  # noqa: E402
from grader.grading.plan import GradingPlan  # noqa: E402
from grader.lab.editions.rl1 import RL1  # noqa: E402
from grader.sandbox import IsolationPolicy  # noqa: E402

NOTEBOOK = ROOT / "submissions" / "editions" / "rl1_template_honest.ipynb"

PLAIN_RUNNER = """
import json, sys, time
import gymnasium
spec = gymnasium.spec("Taxi-v4")
gymnasium.register("Taxi-v3", entry_point=spec.entry_point, max_episode_steps=spec.max_episode_steps,
                   reward_threshold=spec.reward_threshold)
cells = json.load(open(sys.argv[1], encoding="utf-8"))
namespace = {"__name__": "__main__"}
seconds = []
for source in cells:
    started = time.perf_counter()
    exec(compile(source, "<cell>", "exec"), namespace)
    seconds.append(time.perf_counter() - started)
print(json.dumps({"cells": len(cells), "seconds": seconds}))
"""


def code_cells(notebook: Path) -> list[str]:
    """The notebook's code cells, in order (the sample has no IPython magics)."""
    data = json.loads(notebook.read_text(encoding="utf-8"))
    return [
        "".join(cell["source"]) if isinstance(cell["source"], list) else cell["source"]
        for cell in data["cells"]
        if cell["cell_type"] == "code"
    ]


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def plain_run(notebook: Path, directory: Path) -> dict[str, float]:
    """Run All in one plain process; its wall and CPU time."""
    cells = directory / "cells.json"
    cells.write_text(json.dumps(code_cells(notebook)), encoding="utf-8")
    runner = directory / "plain_runner.py"
    runner.write_text(PLAIN_RUNNER, encoding="utf-8")
    environment = {**os.environ, "MPLBACKEND": "Agg", "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy"}
    cpu, started = _children_cpu(), time.perf_counter()
    done = subprocess.run(
        [sys.executable, str(runner), str(cells)],
        capture_output=True,
        text=True,
        env=environment,
        cwd=directory,
        check=False,
    )
    wall = time.perf_counter() - started
    if done.returncode != 0:
        raise SystemExit(f"the plain run failed (exit {done.returncode}): {done.stderr[-3000:]}")
    ran = json.loads(done.stdout.strip().splitlines()[-1])
    return {
        "wall": wall,
        "cpu": _children_cpu() - cpu,
        "cells": ran["cells"],
        "cells_wall": sum(ran["seconds"]),
    }


def graded_run(notebook: Path, seed: int) -> dict[str, object]:
    """The compare problem alone, rl1's default configuration, one worker."""
    plan = GradingPlan.load(RL1.default_config, ["compare"])
    settings = plan.assignment.problems["compare"]
    assert getattr(settings, "run_cells", False), "rl1's default configuration must run the cells"
    started = time.perf_counter()
    (report,) = grade_files([notebook], plan, seed=seed, workers=1, policy=IsolationPolicy.ALLOW_FALLBACK)
    wall = time.perf_counter() - started
    (result,) = report.problems
    return {
        "file_wall": wall,
        "problem_wall": result.timings.wall_seconds if result.timings else float("nan"),
        "status": result.status,
        "student_seconds": result.timings.student_seconds if result.timings else float("nan"),
        "feedback": result.feedback[:300],
    }


def with_episodes(notebook: Path, episodes: int | None, directory: Path) -> Path:
    """The notebook, or a copy whose learners default to `episodes` training episodes."""
    if episodes is None:
        return notebook
    text = notebook.read_text(encoding="utf-8")
    assert text.count("N=70_000") == 2, "expected qlearn's and sarsa0's N=70_000 defaults"
    copy = directory / notebook.name
    copy.write_text(text.replace("N=70_000", f"N={episodes}"), encoding="utf-8")
    return copy


def main() -> None:
    """Measure both, print each and the ratio."""
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--notebook", type=Path, default=NOTEBOOK)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--episodes", type=int, default=None, help="training episodes (default: the lab's)")
    arguments = parser.parse_args()
    kept = Path(tempfile.mkdtemp())
    notebook = with_episodes(arguments.notebook, arguments.episodes, kept)
    print(
        f"notebook {arguments.notebook.name}, N = {arguments.episodes or 70_000}; load average before: {os.getloadavg()}",  # noqa: E501
        flush=True,
    )
    with tempfile.TemporaryDirectory() as temporary:
        plain = plain_run(notebook, Path(temporary))
    print(
        f"plain Run All: {plain['wall']:.1f} s wall, {plain['cpu']:.1f} s CPU "
        f"({plain['cells']:.0f} code cells, {plain['cells_wall']:.1f} s in the cells); load {os.getloadavg()}",  # noqa: E501
        flush=True,
    )
    graded = graded_run(notebook, arguments.seed)
    print(
        f"graded compare (rl1 default configuration, 1 worker): {graded['status']}, problem wall "
        f"{graded['problem_wall']:.1f} s (in the cells and compare() {graded['student_seconds']:.1f} s), "
        f"file wall {graded['file_wall']:.1f} s; load {os.getloadavg()}",
        flush=True,
    )
    print(f"feedback: {graded['feedback']}")
    ratio = float(graded["problem_wall"]) / plain["wall"]  # type: ignore[arg-type]
    print(f"ratio compare problem / plain Run All: {ratio:.2f} (wall)")
    shutil.rmtree(kept)


if __name__ == "__main__":
    main()
