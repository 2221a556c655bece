"""The grader's own cost for each hostile sample next to the honest one, and the endless function's time.

    python bench/hostile.py [--write] [--heading "## Fourth round"]

Each row grades one problem of one sample in a fresh process with the bundled assignment configuration
(`grader.grading.execution.run_problem`, the code an acceptance test runs) and reads that process's own CPU
time and peak resident memory (`getrusage(RUSAGE_SELF)`: the sandbox child, which runs the student's code, is
not counted). So the figures are what the student's code can make the *grader* spend: parsing frames,
replaying episodes, judging. `--write` replaces the `## Integrity and bounded cost` section of
bench/RESULTS.md (or the section `--heading` names). The machine's load average before and after the run is
recorded with the figures: on a shared machine the wall times grow with it, the grader's CPU much less.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from datetime import date
from pathlib import Path

from results_section import replace_section

ROOT = Path(__file__).resolve().parents[1]
HEADING = "## Integrity and bounded cost"

HONEST = "classic_complete.py"
CASES: list[tuple[str, str]] = [
    (HONEST, "cartpole"),
    (HONEST, "car"),
    ("hostile/reset_options_car.py", "car"),
    ("hostile/reset_options_cartpole.py", "cartpole"),
    ("hostile/scouting_car.py", "car"),
    ("hostile/scouting_many_envs.py", "car"),
    ("hostile/zero_step_resets.py", "cartpole"),
    ("hostile/acrobot_in_cartpole.py", "cartpole"),
    ("hostile/patched_dynamics.py", "cartpole"),
    ("hostile/frozenlake_desc.py", "car"),
    ("hostile/endless_car.py", "car"),
    ("hostile/start_printer.py", "cartpole"),
    ("hostile/start_keyed_tapes.py", "cartpole"),
]

_PROBE = """
import json, resource, sys, time
from pathlib import Path
from grader.lab.assignment import load_config
from grader.grading.execution import run_problem
from grader.sandbox import IsolationPolicy
started = time.perf_counter()
run = run_problem(Path(sys.argv[1]), sys.argv[2], config=load_config(), grading_seed=0,
                  policy=IsolationPolicy.ALLOW_FALLBACK)
usage = resource.getrusage(resource.RUSAGE_SELF)
print(json.dumps({"status": run.result.status, "wall": time.perf_counter() - started,
                  "cpu": usage.ru_utime + usage.ru_stime, "peak_mib": usage.ru_maxrss / 1024,
                  "calls": run.result.measurements.get("calls_made", run.result.measurements.get("calls")),
                  "feedback": run.result.feedback[:160]}))
"""


def measure(sample: str, problem: str) -> dict[str, object]:
    """Grade one problem of one sample in a fresh process; its own CPU and peak memory."""
    environment = {**os.environ, "PYTHONPATH": str(ROOT)}
    started = time.perf_counter()
    completed = subprocess.run(
        [sys.executable, "-c", _PROBE, str(ROOT / "submissions" / sample), problem],
        capture_output=True,
        text=True,
        env=environment,
        check=True,
        cwd=ROOT,
    )
    figures: dict[str, object] = json.loads(completed.stdout.strip().splitlines()[-1])
    figures["process_wall"] = time.perf_counter() - started
    return figures


def table(
    rows: list[tuple[str, str, dict[str, object]]],
    call_seconds: float,
    heading: str = HEADING,
    loads: tuple[tuple[float, ...], tuple[float, ...]] | None = None,
) -> str:
    """The section's Markdown."""
    honest = {problem: figures for sample, problem, figures in rows if sample == HONEST}
    command = "python bench/hostile.py --write" + (f' --heading "{heading}"' if heading != HEADING else "")
    load = (
        " Load average (1, 5, 15 min) before the run "
        + ", ".join(f"{value:.2f}" for value in loads[0])
        + ", after it "
        + ", ".join(f"{value:.2f}" for value in loads[1])
        + "."
        if loads is not None
        else ""
    )
    lines = [
        heading,
        "",
        f"`{command}`, {date.today()}, {platform.machine()}, {os.cpu_count()} cores.{load} "
        "One problem per fresh process with the bundled configuration; the grader process's own CPU and "
        "peak RSS (the sandboxed student code is not counted); ratios against the honest lab solution's "
        "same problem, measured in the same run.",
        "",
        "| sample | problem | verdict | calls made | wall s | grader CPU s | x honest CPU "
        "| grader peak MiB |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for sample, problem, figures in rows:
        base = honest[problem]
        ratio = float(figures["cpu"]) / float(base["cpu"])  # type: ignore[arg-type]
        lines.append(
            f"| {sample} | {problem} | {figures['status']} | {figures['calls']} | {figures['wall']:.1f} | "
            f"{figures['cpu']:.2f} | {ratio:.2f} | {figures['peak_mib']:.0f} |"
        )
    endless = next(figures for sample, _, figures in rows if sample.endswith("endless_car.py"))
    lines += [
        "",
        f"The endless `car()` (default config: {call_seconds:g} s per call, 100 calls) is graded in "
        f"{endless['wall']:.1f} s = {float(endless['wall']) / call_seconds:.2f} x the call limit "  # type: ignore[arg-type]
        "(target: under 5x; before issue 8: 100 x).",
        "",
    ]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--write", action="store_true", help="replace the section --heading of RESULTS.md")
    parser.add_argument("--heading", default=HEADING, help=f"the section's heading (default {HEADING!r})")
    arguments = parser.parse_args()
    sys.path.insert(0, str(ROOT))
    from grader.lab.assignment import load_config

    call_seconds = load_config().problem("car").call_seconds
    rows = []
    before = os.getloadavg()
    for sample, problem in CASES:
        figures = measure(sample, problem)
        print(sample, problem, json.dumps(figures), flush=True)
        rows.append((sample, problem, figures))
    text = table(rows, call_seconds, arguments.heading, (before, os.getloadavg()))
    print(text)
    if arguments.write:
        replace_section(arguments.heading, text + "\n")


if __name__ == "__main__":
    main()
