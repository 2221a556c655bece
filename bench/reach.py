"""Figures of issue 10: a notebook grades in the time of the same code as .py; the HTML report's cost.

    python bench/reach.py [--only ID,ID...] [--rounds 1] [--workers 2] [--write]

Grades the lab-literal solution as `submissions/classic_complete.py` and as the notebook
`submissions/notebooks/classic_complete.ipynb` (the same functions among magics, `!pip`, plots, timing and
training cells) alternately, `--rounds` times each, with full isolation, and prints their wall times and
the notebook's build time. Then it draws the HTML report of the .py grading and prints, per problem, the
time to draw its plot and to render its replay GIF, their sizes, and the page's total size. `--write`
replaces the `## Reach (issue 10)` section of bench/RESULTS.md.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
from datetime import date
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from results_section import replace_section  # noqa: E402

from grader.grading.grade import grade_submission  # noqa: E402
from grader.lab.assignment import load_config  # noqa: E402
from grader.lab.problems import PROBLEM_IDS  # noqa: E402
from grader.render.figures import all_figures  # noqa: E402
from grader.render.html import render_html  # noqa: E402
from grader.report import Report  # noqa: E402
from grader.submission.notebook import NotebookModule, build_module  # noqa: E402

PY = ROOT / "submissions" / "classic_complete.py"
NOTEBOOK = ROOT / "submissions" / "notebooks" / "classic_complete.ipynb"
HEADING = "## Reach (issue 10)"


def grading_times(only: list[str], rounds: int, workers: int) -> tuple[dict[str, list[float]], Report]:
    """Wall times of the .py and the notebook, graded alternately; the last .py report."""
    times: dict[str, list[float]] = {"py": [], "ipynb": []}
    report: Report | None = None
    for _ in range(rounds):
        for kind, path in (("py", PY), ("ipynb", NOTEBOOK)):
            started = time.perf_counter()
            graded = grade_submission(path, workers=workers, only=only)
            times[kind].append(time.perf_counter() - started)
            if graded.grader_errors or not graded.full_marks:
                raise SystemExit(f"{path.name} did not get full marks: {graded.to_json()[:2000]}")
            if kind == "py":
                report = graded
    assert report is not None
    return times, report


def section(
    only: list[str], times: dict[str, list[float]], build_ms: float, report: Report, load: str
) -> str:
    """The `## Reach (issue 10)` section of bench/RESULTS.md."""
    config = load_config(None)
    started = time.perf_counter()
    figures = all_figures(report.problems, config)
    page = render_html(report, config, figures)
    total = time.perf_counter() - started
    rows = []
    for problem, drawn in figures.items():
        for figure in drawn:
            kind = "replay GIF" if figure.mime == "image/gif" else "plot PNG"
            rows.append(f"| {problem} | {kind} | {figure.seconds:.2f} | {len(figure.data) / 1000:.1f} |")
    notebook_skipped = build_module(NOTEBOOK.read_bytes(), NOTEBOOK.name)
    skipped = len(notebook_skipped.summary.skipped) if isinstance(notebook_skipped, NotebookModule) else 0
    py_mean, nb_mean = statistics.mean(times["py"]), statistics.mean(times["ipynb"])
    lines = [
        HEADING,
        "",
        f"Measured {date.today().isoformat()} with `python bench/reach.py --only {','.join(only)} "
        f"--rounds {len(times['py'])}` on {platform.machine()}, {os.cpu_count()} cores, full isolation "
        f"({load}).",
        "",
        "### A notebook grades in the time of the same code as .py",
        "",
        f"The lab-literal solution as `.py` and as a notebook (same functions, plus {skipped} skipped "
        "statements: `!pip`, `%matplotlib`, `%%time` and `%timeit` cells, plots, a render loop, a "
        "`find_qvalues` training run), graded alternately:",
        "",
        "| submission | gradings | mean wall (s) | each (s) |",
        "|---|---:|---:|---|",
        f"| classic_complete.py | {len(times['py'])} | {py_mean:.1f} | "
        + ", ".join(f"{value:.1f}" for value in times["py"])
        + " |",
        f"| notebooks/classic_complete.ipynb | {len(times['ipynb'])} | {nb_mean:.1f} | "
        + ", ".join(f"{value:.1f}" for value in times["ipynb"])
        + " |",
        "",
        f"Building the graded module from the notebook takes {build_ms:.1f} ms; the skipped cells are "
        f"never run (difference of the means: {nb_mean - py_mean:+.1f} s).",
        "",
        "### HTML report",
        "",
        "Figures of the .py grading's report (`gymgrade check --html`), drawn one after the other:",
        "",
        "| problem | figure | time to draw (s) | size (kB) |",
        "|---|---|---:|---:|",
        *rows,
        "",
        f"Whole page: {len(page.encode()) / 1000:.0f} kB, {total:.1f} s to draw every figure and render it "
        "(the CartPole and MountainCar plots include 100 episodes of the reference solution, played once "
        "per process). GIFs are capped at 60 frames (every k-th step and the last), 240 pixels wide, one "
        "64-colour palette.",
        "",
    ]
    return "\n".join(lines)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--only", default=",".join(PROBLEM_IDS))
    parser.add_argument("--rounds", type=int, default=1)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--write", action="store_true")
    args = parser.parse_args()
    only = [name for name in args.only.split(",") if name]
    started = time.perf_counter()
    for _ in range(20):
        build_module(NOTEBOOK.read_bytes(), NOTEBOOK.name)
    build_ms = (time.perf_counter() - started) / 20 * 1000
    load_before = os.getloadavg()[0]
    times, report = grading_times(only, args.rounds, args.workers)
    load = f"load average {load_before:.1f} before, {os.getloadavg()[0]:.1f} after"
    text = section(only, times, build_ms, report, load)
    print(text)
    if args.write:
        replace_section(HEADING, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
