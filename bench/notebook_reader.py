"""Figures of issue 22 item 2: the notebook reader's cost in the parent and in its bounded child.

    python bench/notebook_reader.py [--rounds 3] [--write]

Reads every hostile and honest notebook sample (and two generated extremes) through
`grader.submission.notebook.build_module`, `--rounds` times each, and prints per file: its size, the wall
time of a read, the reading child's CPU time (user + system, from the parent's RUSAGE_CHILDREN) and peak
resident memory, the parent's own CPU time per read and its peak memory over the whole run, and the outcome (a
module, or the verdict). The parent only spawns the child and validates its reply, so its figures must
stay flat whatever the file. `--write` replaces the `## Fourth round: notebook reader` section of
bench/RESULTS.md.
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import statistics
import sys
import time
from datetime import date
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import nbformat  # noqa: E402
from nbformat.v4 import new_code_cell, new_notebook  # noqa: E402
from results_section import replace_section  # noqa: E402

from grader.lab.problems import PROBLEM_IDS  # noqa: E402
from grader.submission.notebook import NotebookModule, build_module  # noqa: E402
from grader.submission.notebook.bounded import CPU_SECONDS, MEMORY_BYTES  # noqa: E402

HEADING = "## Fourth round: notebook reader"
SAMPLES = [
    *sorted((ROOT / "submissions" / "notebooks").glob("*.ipynb")),
    *sorted((ROOT / "submissions" / "hostile").glob("*.ipynb")),
]


def generated() -> dict[str, bytes]:
    """Two extremes no sample file holds: the code budget filled with shell escapes, and 95 cells of
    199,000 characters (a 19 MB notebook, refused by the code budget before parsing)."""
    bangs = ["\n".join(["!echo hi"] * 20_000)] * 10
    big = ["x = [" + "1," * 99_500 + "]"] * 95
    return {
        "generated: 200,000 shell escapes": nbformat.writes(
            new_notebook(cells=[new_code_cell(c) for c in bangs])
        ).encode(),
        "generated: 95 cells of 199,000 chars": nbformat.writes(
            new_notebook(cells=[new_code_cell(c) for c in big])
        ).encode(),
    }


def measure(name: str, data: bytes, rounds: int) -> dict[str, object]:
    walls, child_cpu, parent_cpu = [], [], []
    outcome = ""
    for _ in range(rounds):
        children = resource.getrusage(resource.RUSAGE_CHILDREN)
        own = resource.getrusage(resource.RUSAGE_SELF)
        started = time.perf_counter()
        built = build_module(data, name, PROBLEM_IDS)
        walls.append(time.perf_counter() - started)
        children_after = resource.getrusage(resource.RUSAGE_CHILDREN)
        own_after = resource.getrusage(resource.RUSAGE_SELF)
        child_cpu.append(
            children_after.ru_utime + children_after.ru_stime - children.ru_utime - children.ru_stime
        )
        parent_cpu.append(own_after.ru_utime + own_after.ru_stime - own.ru_utime - own.ru_stime)
        outcome = (
            f"module ({built.summary.kept_statements:,} kept, {len(built.summary.skipped):,} skipped)"
            if isinstance(built, NotebookModule)
            else f"{built.status}: {built.message[:70]}..."
        )
    return {
        "name": name,
        "bytes": len(data),
        "wall": statistics.median(walls),
        "child_cpu": statistics.median(child_cpu),
        "parent_cpu": statistics.median(parent_cpu),
        "child_rss_mib": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024,
        "outcome": outcome,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--write", action="store_true")
    arguments = parser.parse_args()
    inputs = {path.relative_to(ROOT / "submissions").as_posix(): path.read_bytes() for path in SAMPLES}
    inputs.update(generated())
    rows = [measure(name, data, arguments.rounds) for name, data in inputs.items()]
    peak_parent = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    load = os.getloadavg()[0]
    lines = [
        HEADING,
        "",
        f"`python bench/notebook_reader.py --rounds {arguments.rounds}` on {date.today()}, "
        f"{platform.python_implementation()} {platform.python_version()}, {os.cpu_count()} cores, "
        f"load average {load:.1f} at the end (the machine was shared: wall times are inflated, CPU times are not). "  # noqa: E501
        f"Each file is read {arguments.rounds} times through "
        f"`grader.submission.notebook.build_module` (the bounded "
        f"child: {CPU_SECONDS} s CPU, {MEMORY_BYTES // 2**20:,} MiB address space); medians. "
        "Child peak RSS is the largest of any child so far (RUSAGE_CHILDREN), so it only grows down the table.",  # noqa: E501
        "",
        "| file | bytes | wall s | child CPU s | parent CPU s | child peak RSS MiB | outcome |",
        "|---|---:|---:|---:|---:|---:|---|",
    ]
    for row in rows:
        lines.append(
            f"| {row['name']} | {row['bytes']:,} | {row['wall']:.2f} | {row['child_cpu']:.2f} | "
            f"{row['parent_cpu']:.3f} | {row['child_rss_mib']:.0f} | {row['outcome']} |"
        )
    lines += ["", f"Parent peak RSS over the whole run: {peak_parent:.0f} MiB.", ""]
    text = "\n".join(lines)
    print(text)
    if arguments.write:
        replace_section(HEADING, text + "\n")


if __name__ == "__main__":
    main()
