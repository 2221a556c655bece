"""Sandbox overhead against a plain subprocess running the same function, and (bench/replay.py) replay cost.

Two figures, each the median over `--repetitions`:
  * per child (cold): start, import the submission, one call, stop -- a `Sandbox` with every isolation
    layer against `python -c` importing the same file and calling the same function;
  * per call (warm): one more call in a running child -- `Sandbox.call` against a plain long-lived
    subprocess answering the same call over a pipe (JSON lines, no isolation, no framing).
Sandboxed and plain runs alternate, so that load from other processes hits both alike; the overhead is
the median of the paired differences. Then bench/replay.py prints the replay cost of 100 CartPole
episodes.

    python bench/sandbox.py [--repetitions 15] [--replay-rounds 5]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

from grader.sandbox import Call, Limits, Sandbox, probe_isolation

REPLAY_SCRIPT = Path(__file__).resolve().parent / "replay.py"

SUBMISSION = textwrap.dedent("""
    import gymnasium
    import numpy as np


    def noop(x):
        return x + 1
""")
PLAIN_SERVER = textwrap.dedent("""
    import json, runpy, sys
    functions = runpy.run_path(sys.argv[1], run_name="submission")
    print("ready", flush=True)
    for line in sys.stdin:
        call = json.loads(line)
        print(json.dumps(functions[call["function"]](*call["args"])), flush=True)
""")
WARM_CALLS = 200


def _median_ms(samples: list[float]) -> float:
    return statistics.median(samples) * 1000


def cold_sandbox(submission: Path, limits: Limits) -> float:
    """Seconds to start a sandboxed child, import, make one call and stop it."""
    started = time.perf_counter()
    with Sandbox(submission, seed=0, limits=limits) as sandbox:
        outcome = sandbox.call(Call("noop", (1,)))
    if outcome.value != 2:
        raise RuntimeError(f"the sandboxed call failed: {outcome.message}")
    return time.perf_counter() - started


def cold_plain(submission: Path) -> float:
    """Seconds for a plain subprocess to import the same file and make the same call."""
    code = f"import runpy; print(runpy.run_path({str(submission)!r}, run_name='submission')['noop'](1))"
    started = time.perf_counter()
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    if result.stdout.strip() != "2":
        raise RuntimeError(f"the plain call failed: {result.stderr}")
    return time.perf_counter() - started


def warm_sandbox(submission: Path, limits: Limits) -> list[float]:
    """Seconds per call in one running sandboxed child."""
    with Sandbox(submission, seed=0, limits=limits) as sandbox:
        sandbox.call(Call("noop", (0,)))
        times = []
        for number in range(WARM_CALLS):
            started = time.perf_counter()
            sandbox.call(Call("noop", (number,)))
            times.append(time.perf_counter() - started)
    return times


def warm_plain(submission: Path) -> list[float]:
    """Seconds per call in one plain long-lived subprocess."""
    with subprocess.Popen(
        [sys.executable, "-c", PLAIN_SERVER, str(submission)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    ) as server:
        if server.stdin is None or server.stdout is None or server.stdout.readline().strip() != "ready":
            raise RuntimeError("the plain server did not start")
        times = []
        for number in range(WARM_CALLS):
            started = time.perf_counter()
            server.stdin.write(json.dumps({"function": "noop", "args": [number]}) + "\n")
            server.stdin.flush()
            json.loads(server.stdout.readline())
            times.append(time.perf_counter() - started)
        server.stdin.close()
    return times


def main() -> None:
    """Print the figures for the `## Sandbox` section of bench/RESULTS.md."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repetitions", type=int, default=15)
    parser.add_argument("--replay-rounds", type=int, default=5)
    arguments = parser.parse_args()
    report = probe_isolation()
    print("isolation:\n" + report.summary())
    limits = Limits(call_seconds=30, import_seconds=30)
    with tempfile.TemporaryDirectory() as directory:
        submission = Path(directory) / "submission.py"
        submission.write_text(SUBMISSION)
        cold_plain(submission)
        cold_sandbox(submission, limits)
        cold_pairs = [
            (cold_sandbox(submission, limits), cold_plain(submission)) for _ in range(arguments.repetitions)
        ]
        warm_pairs = [
            (statistics.median(warm_sandbox(submission, limits)), statistics.median(warm_plain(submission)))
            for _ in range(arguments.repetitions)
        ]
    for title, pairs, digits in (
        ("per child (start + import + 1 call + stop)", cold_pairs, 1),
        (f"per call in a running child ({WARM_CALLS} calls per repetition)", warm_pairs, 3),
    ):
        sandboxed = _median_ms([pair[0] for pair in pairs])
        plain = _median_ms([pair[1] for pair in pairs])
        overhead = _median_ms([pair[0] - pair[1] for pair in pairs])
        print(f"{title}, median of {arguments.repetitions}:")
        print(
            f"  sandboxed {sandboxed:8.{digits}f} ms   plain subprocess {plain:8.{digits}f} ms   "
            f"overhead {overhead:8.{digits}f} ms (target <= 100 ms)"
        )
    sys.stdout.flush()
    subprocess.run([sys.executable, str(REPLAY_SCRIPT), "--rounds", str(arguments.replay_rounds)], check=True)


if __name__ == "__main__":
    main()
