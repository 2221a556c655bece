"""Issue 44's class figure: a class of current-edition notebooks graded by `gymgrade grade`, projected to 300.

    python bench/class_grading.py [--students 24] [--workers 2] [--seed 44] [--write]

1. Builds a class of K notebooks (default 24, one pytest chunk of `grader.grading.batch`) in the plain-folder
   layout `class/<student>/gymnasium.ipynb`, each a variant of the honest current-edition notebook
   `submissions/editions/rl1_template_honest.ipynb` (the course's template with the lab's own cells, the
   learners' default N = 70 000): the student's name, the learners' default alpha and gamma, a seed line
   or not, `%matplotlib inline` or not, the tables' names (renamed throughout), the progress printing; every
   fifth notebook (K / 5 of them) carries one of the lab's typical mistakes (`MISTAKES`).
2. Grades the class with `gymgrade grade --edition rl1` (the edition's default configuration: compare()
   with the grader's tables bound, `bind_tables = true`), full isolation, `--workers N`, timing the wall and
   the CPU of every process of the run (`bench/cpu_group.py`: a cgroup v1 `cpuacct` group, else
   `RUSAGE_CHILDREN`), the machine's 1-minute load average sampled every 5 s, each problem's wall from the
   reports.
3. Prints (and with `--write` writes as `## Class of current-edition notebooks` in bench/RESULTS.md) the
   per-notebook figures and the projection to 300 notebooks on one 2-core machine: 300 x the CPU per
   notebook / 2 (a busy machine drains 2 core-seconds a second; load cannot stretch CPU), and 300 x the
   wall per notebook as measured (stretched by whatever else ran). Target: at most 90 minutes.
"""

from __future__ import annotations

import argparse
import contextlib
import ctypes
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time
from collections import Counter, defaultdict
from datetime import UTC, datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BENCH = Path(__file__).resolve().parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(BENCH))

from class_throughput import LoadSampler, children_cpu, reap_orphans, row  # noqa: E402
from cpu_group import CpuGroup  # noqa: E402
from results_section import replace_section  # noqa: E402

HEADING = "## Class of current-edition notebooks"
NOTEBOOK = ROOT / "submissions" / "editions" / "rl1_template_honest.ipynb"
PROJECTED_CLASS = 300
TARGET_MINUTES = 90.0
NAMES = (
    "ada", "bruno", "chen", "dalia", "emeka", "fatima", "goran", "hana", "ivan", "jun", "kofi", "lena",
    "mateo", "nadia", "oskar", "priya", "quinn", "rosa", "sven", "tariq", "uma", "vera", "wei", "yusuf",
)  # fmt: skip
ALPHAS = (0.1, 0.2, 0.15, 0.1, 0.25)
GAMMAS = (0.6, 0.7, 0.9, 0.8, 0.6)
MISTAKES: dict[str, tuple[str, str]] = {
    "blackjack draws while the hand is below n": (
        "action = 1 if hand <= n else 0",
        "action = 1 if hand < n else 0",
    ),
    "random_blackjack counts draws as wins": (
        "        if reward > 0:\n            wins += 1\n    env.close()\n    return wins / n",
        "        if reward >= 0:\n            wins += 1\n    env.close()\n    return wins / n",
    ),
    "cartpole pushes against the pole": (
        "action = 1 if state[3] > 0 else 0",
        "action = 0 if state[3] > 0 else 1",
    ),
    "compare() returns the means swapped": (
        "    for table in (q_table_decay, sarsa_table_decay):",
        "    for table in (sarsa_table_decay, q_table_decay):",
    ),
    "epsilon_decay never reaches epsilon_end (divides by N + 1)": (
        "delta = (epsilon_start - epsilon_end) / N",
        "delta = (epsilon_start - epsilon_end) / (N + 1)",
    ),
}
"""One typical mistake per flawed notebook: the honest text and its replacement, in the first cell holding it
(compare()'s text comes after taxi()'s, which ends alike: the compare mistake's text starts at its def)."""


def _source(cell: dict[str, object]) -> str:
    source = cell["source"]
    return "".join(source) if isinstance(source, list) else str(source)


def _set(cell: dict[str, object], text: str) -> None:
    cell["source"] = text.splitlines(keepends=True)


def variant(notebook: dict[str, object], index: int) -> tuple[dict[str, object], str]:
    """The honest notebook as student `index` might hand it in, and the mistake it carries ('' if none)."""
    data = json.loads(json.dumps(notebook))
    cells: list[dict[str, object]] = data["cells"]  # type: ignore[assignment]
    name = NAMES[index % len(NAMES)]
    mistake = ""
    if index % 5 == 4:
        mistake = list(MISTAKES)[(index // 5) % len(MISTAKES)]
    alpha, gamma = ALPHAS[index % len(ALPHAS)], GAMMAS[(index // 2) % len(GAMMAS)]
    renamed = index % 3 == 1
    applied = False
    for cell in cells:
        text = _source(cell)
        if cell["cell_type"] == "markdown" and text.startswith("C. Student"):
            text = text.replace("C. Student", f"{name.capitalize()} Student{index:02d}")
        if cell["cell_type"] == "code":
            if text.startswith("import gymnasium"):
                if index % 4 == 0:
                    text = "%matplotlib inline\n" + text
                if index % 2 == 0:
                    text += f"\nrandom.seed({index})\nnp.random.seed({index})"
            text = text.replace("alpha=.1, gamma=.6,", f"alpha={alpha}, gamma={gamma},")
            text = text.replace("alpha=0.1, gamma=0.6,", f"alpha={alpha}, gamma={gamma},")
            if index % 3 == 2:
                quieter = "        if i % 100 == 0:\n            display.clear_output(wait=True)\n"
                text = text.replace(quieter, "        if i % 1000 == 0:\n")
            honest, wrong = MISTAKES.get(mistake, ("", ""))
            if mistake and honest in text and not applied:
                text, applied = text.replace(honest, wrong), True
            if renamed:
                text = re.sub(r"\bq_table_decay\b", "q_decay", text)
                text = re.sub(r"\bsarsa_table_decay\b", "sarsa_decay", text)
        _set(cell, text)
    whole = json.dumps(data)
    assert "N=70_000" in whole, "every notebook keeps the lab's N = 70 000"
    assert applied or not mistake, f"mistake not applied: {mistake}"
    return data, mistake


def build_class(folder: Path, students: int) -> dict[str, str]:
    """`folder/<student>/gymnasium.ipynb` for each student; the mistake each carries."""
    notebook = json.loads(NOTEBOOK.read_text(encoding="utf-8"))
    mistakes = {}
    for index in range(students):
        student = f"{NAMES[index % len(NAMES)]}{index:02d}"
        data, mistake = variant(notebook, index)
        (folder / student).mkdir(parents=True)
        (folder / student / "gymnasium.ipynb").write_text(json.dumps(data, indent=1), encoding="utf-8")
        mistakes[student] = mistake
    return mistakes


def grade_class(folder: Path, out: Path, workers: int, seed: int) -> tuple[float, float, bool, str]:
    """`gymgrade grade` of the class: wall, CPU of its processes, whether that CPU is the cgroup's, stdout."""
    command = [sys.executable, "-m", "grader", "grade", str(folder), "--out", str(out)]
    command += ["--edition", "rl1", "--seed", str(seed), "--workers", str(workers)]
    group = CpuGroup("class-grading")
    cpu_before, started = children_cpu(), time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, check=False, preexec_fn=group.join)
    wall = time.perf_counter() - started
    reap_orphans()
    grouped = group.seconds()
    cpu = grouped if grouped is not None else children_cpu() - cpu_before
    group.remove()
    if done.returncode not in (0, 1):
        raise SystemExit(f"gymgrade grade failed (exit {done.returncode}): {done.stderr[-3000:]}")
    return wall, cpu, grouped is not None, done.stdout


def read_reports(out: Path) -> tuple[Counter[str], dict[str, list[float]], list[dict[str, float]]]:
    """Problem statuses, each problem's walls, each notebook's grading timings, from the batch's reports."""
    statuses: Counter[str] = Counter()
    walls: dict[str, list[float]] = defaultdict(list)
    timings: list[dict[str, float]] = []
    for path in sorted(out.glob("*.json")):
        report = json.loads(path.read_text(encoding="utf-8"))
        for problem in report["problems"]:
            statuses[f"{problem['id']}: {problem['status']}"] += 1
            wall = (problem.get("timings") or {}).get("wall_seconds")
            if wall is not None:
                walls[problem["id"]].append(float(wall))
        if report.get("timings"):
            timings.append(report["timings"])
    return statuses, walls, timings


def section(
    *,
    command: str,
    students: int,
    mistakes: dict[str, str],
    workers: int,
    wall: float,
    cpu: float,
    cgroup: bool,
    load: LoadSampler,
    statuses: Counter[str],
    walls: dict[str, list[float]],
    timings: list[dict[str, float]],
) -> str:
    """The `## Class of current-edition notebooks` section."""
    cores = len(os.sched_getaffinity(0))
    per_cpu, per_wall = cpu / students, wall / students
    drain = PROJECTED_CLASS * per_cpu / 2 / 60
    stretched = PROJECTED_CLASS * per_wall / 60
    busy = statistics.median(load.samples) > workers + 0.5
    stamp = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    flawed = sorted(mistake for mistake in mistakes.values() if mistake)
    problems = sorted(walls, key=lambda name: -statistics.median(walls[name]))
    by_problem: dict[str, Counter[str]] = defaultdict(Counter)
    for key, count in statuses.items():
        name, status = key.split(": ", 1)
        by_problem[name][status] += count
    lines = [
        HEADING,
        f"`{command}`, {stamp}, {platform.machine()}, {cores} cores, full isolation, `--workers {workers}`, "
        f"rl1's default configuration (compare() with bound tables). Machine load during the run: "
        f"{load.summary()}"
        + (
            f"; **shared with other jobs (median above this run's {workers} workers)**: the wall figures are "
            "stretched by them, the CPU figures are not."
            if busy
            else "."
        ),
        "",
        f"A class of {students} notebooks (`class/<student>/gymnasium.ipynb`), each a variant of "
        "`submissions/editions/rl1_template_honest.ipynb` (the lab's cells, N = 70 000): names, the "
        "learners' alpha and gamma, seed lines, `%matplotlib inline`, the tables' names, the progress "
        "printing; "
        f"{len(flawed)} with a typical mistake ({'; '.join(flawed)}).",
        "",
        row("figure", "measured", f"projected: {PROJECTED_CLASS} notebooks, 1 x 2 cores", "target"),
        row("---", "---:", "---:", "---"),
        row(
            "CPU per notebook (every process of the run)" + ("" if cgroup else ", RUSAGE_CHILDREN"),
            f"{per_cpu:.1f} s",
            f"**{drain:.1f} min** (300 x {per_cpu:.1f} s / 2 cores)",
            f"<= {TARGET_MINUTES:.0f} min: {'met' if drain <= TARGET_MINUTES else 'NOT met'}",
        ),
        row(
            "wall per notebook (class wall / notebooks)",
            f"{per_wall:.1f} s ({wall:.0f} s for {students})",
            f"{stretched:.1f} min (at this run's load)",
            f"{'met' if stretched <= TARGET_MINUTES else 'not met'} at this load",
        ),
        row("cores busy (CPU / wall)", f"{cpu / wall:.2f} of {cores}", "", ""),
        row(
            "per notebook, from its report: its problems' walls summed (the student's code in them)",
            f"median {statistics.median(t['check_seconds'] for t in timings):.1f} s "
            f"({statistics.median(t['student_seconds'] for t in timings):.1f} s)",
            "",
            "",
        ),
    ]
    parts = []
    for name in problems:
        flawed_here = sum(count for status, count in by_problem[name].items() if status != "passed")
        parts.append(
            f"{name} {statistics.median(walls[name]):.1f} ({max(walls[name]):.1f})"
            + (f", {flawed_here} not passed" if flawed_here else "")
        )
    lines += [
        "",
        "Per problem, its wall in its sandbox child (median (max) s, from the reports; every other notebook "
        "passed it): " + "; ".join(parts) + ".",
        "",
        "Projection: gradings are CPU-bound and independent, so one 2-core machine kept busy drains "
        f"{PROJECTED_CLASS} x (CPU per notebook) / 2; the batch grades chunks of 24 notebooks, so a class of "
        f"{PROJECTED_CLASS} is {-(-PROJECTED_CLASS // 24)} chunks like this run's (each chunk's tail is its "
        "shortest problems).",
        "",
    ]
    return "\n".join(lines)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument(
        "--students", type=int, default=24, help="K, the class size (default 24, at least 20)"
    )
    parser.add_argument("--workers", type=int, default=len(os.sched_getaffinity(0)))
    parser.add_argument("--seed", type=int, default=44)
    parser.add_argument("--keep", type=Path, default=None, help="build the class and its gradebook here")
    parser.add_argument("--write", action="store_true")
    args = parser.parse_args()
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(36, 1, 0, 0, 0)  # PR_SET_CHILD_SUBREAPER
    with tempfile.TemporaryDirectory(prefix="gymgrade-notebooks-") as scratch:
        root = args.keep or Path(scratch)
        folder, out = root / "class", root / "gradebook"
        mistakes = build_class(folder, args.students)
        out.mkdir(parents=True)
        print(f"grading {args.students} notebooks; load {os.getloadavg()}", flush=True)
        with LoadSampler() as load:
            wall, cpu, cgroup, stdout = grade_class(folder, out, args.workers, args.seed)
        print(stdout[-1000:], flush=True)
        statuses, walls, timings = read_reports(out)
    command = " ".join(["python", "bench/class_grading.py", *sys.argv[1:]])
    text = section(
        command=command,
        students=args.students,
        mistakes=mistakes,
        workers=args.workers,
        wall=wall,
        cpu=cpu,
        cgroup=cgroup,
        load=load,
        statuses=statuses,
        walls=walls,
        timings=timings,
    )
    print(text)
    if args.write:
        replace_section(HEADING, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
