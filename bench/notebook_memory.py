"""Figures of issue 33 item "a notebook of empty JSON objects": the parent's peak memory per notebook.

    python bench/notebook_memory.py [--before REV] [--write]

A valid notebook of 19.9 MB (the lab's classic notebook with 6.6 million empty JSON objects among its
cells, generated here) is read by edition detection, grading (the module the sandbox imports) and
similarity, each alone in a fresh process, and then a whole `gymgrade grade DIR --similarity --only
random_blackjack` runs on a class of two honest notebooks with and without it. Each figure is the
measuring process's own peak resident memory (VmHWM: the parent; the bounded reading child is not in it),
with the wall time. `--before REV` measures a `git archive` of REV the same way (the tree before
the change); `--write` replaces the `## Fifth round: notebook memory` section of bench/RESULTS.md.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
from datetime import date
from pathlib import Path
from typing import Any

from results_section import replace_section

ROOT = Path(__file__).resolve().parents[1]
HEADING = "## Fifth round: notebook memory"
HONEST = {
    "alice.ipynb": ROOT / "submissions" / "notebooks" / "classic_complete.ipynb",
    "bob.ipynb": ROOT / "submissions" / "notebooks" / "bad_metadata.ipynb",
}
TARGET_BYTES = 19_900_000

STEPS = {
    "detection": "from grader.lab.editions.detection import detect_edition\nresult = detect_edition(path)",
    "grading (module)": (
        "from grader.submission.notebook import build_module\nfrom grader.grading.plan import GradingPlan\n"
        "result = build_module(path.read_bytes(), path.name, GradingPlan.load(None, None).problems)"
    ),
    "similarity": "from grader.classroom.similarity.sources import read_source\nresult = read_source(path)",
    "grade --similarity": (
        "from grader.cli import main\n"
        "result = main(['grade', str(path), '--out', str(out), '--similarity', '--only', "
        "'random_blackjack', '--seed', '1'])"
    ),
}
MEASURE = """
import json, re, resource, sys, time
from pathlib import Path
path, out = Path(sys.argv[1]), Path(sys.argv[2])


def peak():
    # VmHWM: this process's own peak since its exec (ru_maxrss starts from its parent's size at the fork)
    try:
        status = Path("/proc/self/status").read_text()
        return int(re.search(r"VmHWM:\\s+(\\d+) kB", status).group(1)) / 1024
    except OSError:
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


import grader.cli, grader.lab.editions.detection, grader.submission.notebook
import grader.classroom.similarity.sources, grader.grading.plan
before = peak()
started = time.perf_counter()
{step}
wall = time.perf_counter() - started
print(json.dumps({{"before": before, "peak": peak(), "wall": wall, "result": str(result)[:300],
                  "grader": grader.cli.__file__}}))
"""


def write_hostile_notebook(path: Path) -> None:
    """The lab's classic notebook with empty objects among its cells, up to `TARGET_BYTES`, written in
    pieces (this process stays small: a child's peak RSS starts from its parent's size at the fork)."""
    text = json.dumps(json.loads(HONEST["alice.ipynb"].read_text(encoding="utf-8")))
    at = text.index('"cells": [') + len('"cells": [')
    objects = (TARGET_BYTES - len(text)) // 3
    with path.open("w", encoding="utf-8") as stream:
        stream.write(text[:at])
        for start in range(0, objects, 100_000):
            stream.write("{}," * min(100_000, objects - start))
        stream.write(text[at:])


def measure(source: Path, step: str, path: Path, scratch: Path) -> dict[str, Any]:
    out = scratch / f"out-{len(list(scratch.iterdir()))}"
    completed = subprocess.run(
        [sys.executable, "-c", MEASURE.format(step=STEPS[step]), str(path), str(out)],
        cwd=source,
        env={**os.environ, "PYTHONPATH": str(source)},
        capture_output=True,
        text=True,
        check=True,
    )
    figures: dict[str, Any] = json.loads(completed.stdout.splitlines()[-1])
    if not Path(str(figures["grader"])).is_relative_to(source):
        raise RuntimeError(f"measured {figures['grader']}, not the tree in {source}")
    return figures


def run(source: Path, scratch: Path) -> list[tuple[str, str, dict[str, Any]]]:
    honest = scratch / "honest"
    hostile = scratch / "hostile"
    for folder in (honest, hostile):
        folder.mkdir()
        for name, sample in HONEST.items():
            (folder / name).write_bytes(sample.read_bytes())
    write_hostile_notebook(hostile / "mallory.ipynb")
    rows = []
    for step in ("detection", "grading (module)", "similarity"):
        for label, path in (
            ("honest notebook", honest / "alice.ipynb"),
            ("19.9 MB notebook", hostile / "mallory.ipynb"),
        ):
            rows.append((step, label, measure(source, step, path, scratch)))
    for label, folder in (("class of 2 honest", honest), ("same + the 19.9 MB notebook", hostile)):
        rows.append(("grade --similarity", label, measure(source, "grade --similarity", folder, scratch)))
    return rows


def table(title: str, rows: list[tuple[str, str, dict[str, Any]]]) -> list[str]:
    lines = [
        title,
        "",
        "| step | input | parent before MiB | parent peak MiB | growth MiB | wall s | outcome |",
        "|---|---|---:|---:|---:|---:|---|",
    ]
    for step, label, figures in rows:
        outcome = str(figures["result"]).replace("|", "/").replace("\n", " ")[:110]
        lines.append(
            f"| {step} | {label} | {figures['before']:.0f} | {figures['peak']:.0f} | "
            f"{figures['peak'] - figures['before']:.0f} | {figures['wall']:.2f} | {outcome} |"
        )
    return [*lines, ""]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", default=None, metavar="REV", help="also measure this revision")
    parser.add_argument("--write", action="store_true")
    arguments = parser.parse_args()
    lines = [
        HEADING,
        "",
        f"`python bench/notebook_memory.py{' --before ' + arguments.before if arguments.before else ''}` on "
        f"{date.today()}, {platform.python_implementation()} {platform.python_version()}, {os.cpu_count()} cores, "  # noqa: E501
        f"load average {os.getloadavg()[0]:.1f} (shared machine: wall times are inflated). "
        "Peak resident memory of the measuring process itself (VmHWM; the bounded reading child is "
        'not counted), each row in a fresh process; "before" is after imports, "peak" after the step.',
        "",
    ]
    with tempfile.TemporaryDirectory(prefix="gymgrade-bench-") as temporary:
        scratch = Path(temporary)
        if arguments.before:
            old = scratch / "before-tree"
            old.mkdir()
            subprocess.run(
                f"git -C '{ROOT}' archive '{arguments.before}' | tar -x -C '{old}'", shell=True, check=True
            )
            (scratch / "before").mkdir()
            lines += table(f"Before ({arguments.before}):", run(old, scratch / "before"))
        (scratch / "now").mkdir()
        lines += table("Now:", run(ROOT, scratch / "now"))
    text = "\n".join(lines)
    print(text)
    if arguments.write:
        replace_section(HEADING, text + "\n")


if __name__ == "__main__":
    main()
