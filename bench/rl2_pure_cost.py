"""What grading the second lab's pure problems costs (issue 35): wall and student seconds per problem.

Grades, through the real sandbox with each edition's default configuration, the honest files and the sample
whose policy iteration never converges on the lab's example (its two timeouts, one per reading, are the
problem's largest cost), and prints each
problem's calls, wall seconds (child start, import, every call, judging) and the seconds spent in the
student's functions. Timings are measurements of this machine at this load, never assertions.

    python bench/rl2_pure_cost.py            # about a minute
    python bench/rl2_pure_cost.py --write    # and replace the section of bench/RESULTS.md
"""

from __future__ import annotations

import argparse
import os
import sys
import textwrap
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.results_section import replace_section
from grader.grading.grade import grade_files
from grader.grading.plan import GradingPlan
from grader.lab.editions import edition_of
from grader.sandbox import IsolationPolicy

ROOT = Path(__file__).resolve().parents[1]
HEADING = "## Second lab: the cost of the pure problems (issue 35)"
DESCRIPTION = (
    "`python bench/rl2_pure_cost.py`: each file graded through the sandbox with its edition's default "
    "configuration, grading seed 35 (the nine public MDPs of the lab's kind and three held-out random ones "
    "drawn from each problem's seed), 2 workers, on {cores} cores shared with other work. "
    "Wall: the problem's child start, import, every call and judging; "
    "student: seconds inside the submission's functions. "
    "A problem's calls all run in its one child; "
    "a call that times out (policy_iteration's alternating start on the lab's example at discount 1, "
    "`call_seconds = 20`, once in each of its two readings: the student's own steps, then the grader's) "
    "restarts it for the next call."
)
FILES = (
    ("v2024", "submissions/rl2/honest_v2024.py"),
    ("v2018", "submissions/rl2/honest_v2018.py"),
    ("v2026", "submissions/rl2/mistakes/policy_iteration_alternating_start.py"),
)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="replace the section of bench/RESULTS.md")
    arguments = parser.parse_args()
    started = time.perf_counter()
    rows = []
    for edition, file in FILES:
        plan = GradingPlan.load(edition_of(edition).default_config, None)
        (report,) = grade_files(
            [ROOT / file], plan, seed=35, workers=2, policy=IsolationPolicy.ALLOW_FALLBACK
        )
        for problem in report.problems:
            calls = problem.measurements.get("mdps_graded") or problem.measurements.get("calls_graded") or "-"
            rows.append(
                f"| {file.removeprefix('submissions/rl2/')} ({edition}) | {problem.id} | {problem.status} | "
                f"{calls} | {problem.timings.wall_seconds:.1f} | {problem.timings.student_seconds:.1f} |"
            )
    took = time.perf_counter() - started
    text = "\n".join(
        [
            HEADING,
            "",
            textwrap.fill(DESCRIPTION.format(cores=os.cpu_count()), width=105),
            "",
            "| file | problem | status | calls | wall s | student s |",
            "|---|---|---|---|---|---|",
            *rows,
            "",
            f"Took {took:.0f} s.",
            "",
        ]
    )
    print(text)
    if arguments.write:
        replace_section(HEADING, text)


if __name__ == "__main__":
    main()
