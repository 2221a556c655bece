"""What parsing a result frame costs the grader, before and after frames were bounded (issue 8).

Frames measured: an honest Taxi frame (`taxi(q_table)` of submissions/gymnasium_complete.py, 20 000
episodes), an honest Blackjack frame (`blackjack(13)`, 10 000 games), both recorded by the real child
harness, and the forged frame of submissions/hostile/forged_big_frame.py (24 MB of `[{},{},...]` with
the right id and nonce). Each is handled in a fresh subprocess, which reports its wall time and how much
the peak of the Python memory it allocated (tracemalloc, in a second run: tracing slows parsing; the
kernel's ru_maxrss proved unreliable here, missing peaks of freshly allocated objects):

  * before: `parse_payload` (json.loads of the whole frame), then `episodes_from_plain`: what the
    runner did before issue 8;
  * after: the runner's path now: `FrameLimits.excess` (size and structural characters, no parsing),
    then, only when within the call's limits, the same parse and `episodes_from_plain` with the budget.

The forged frame is measured against two calls: one without a budget (the sandbox-wide limits) and one
with a CartPole-sized budget (4 episodes, 1 000 steps); the runner refuses the latter at the frame's
header without reading its body.

    python bench/frames.py [--repetitions 3]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "grader" / "sandbox"))
sys.path.insert(0, str(ROOT))

from child_client import ChildClient  # noqa: E402

from grader.sandbox.child import frames  # noqa: E402

MEASURE = """
import json, sys, time, tracemalloc
sys.path.insert(0, {root!r})
from grader.sandbox.child.budget import WireBudget, frame_limits
from grader.sandbox.child.errors import ProtocolError
from grader.sandbox.child.frames import parse_payload
from grader.sandbox.episode_log import episodes_from_plain
from grader.sandbox.limits import CallBudget

mode, path, budget, trace = sys.argv[1], sys.argv[2], json.loads(sys.argv[3]), sys.argv[4] == "trace"
payload = open(path, "rb").read()
if trace:
    tracemalloc.start()
started = time.perf_counter()
verdict = "parsed"
if mode == "after":
    wire = None if budget is None else WireBudget(*budget)
    limits = frame_limits(wire, record=True, max_frame=256 << 20)
    excess = limits.excess(payload)
    if excess:
        verdict = "refused: " + excess
if verdict == "parsed":
    try:
        frame = parse_payload(payload)
        call_budget = None if budget is None or mode == "before" else CallBudget(*budget)
        episodes = episodes_from_plain(frame["episodes"], call_budget)  # frame kept alive until the end
        verdict = f"parsed: {{len(episodes)}} episodes"
    except (ProtocolError, KeyError, TypeError) as error:
        verdict = f"refused after parsing: {{error}}"
seconds = time.perf_counter() - started
peak = tracemalloc.get_traced_memory()[1] / (1 << 20) if trace else 0.0
print(json.dumps({{"seconds": seconds, "peak_mib": peak, "verdict": verdict[:90]}}))
"""


def honest_frame(function: str, args: tuple[object, ...]) -> bytes:
    """The payload of one call of the complete gymnasium solution, as the child harness sends it."""
    captured: list[bytes] = []
    read_frame = frames.read_frame

    def capturing_read_frame(stream, max_frame=frames.DEFAULT_MAX_FRAME):  # type: ignore[no-untyped-def]
        header = stream.read(frames.HEADER.size)
        if not header:
            return None
        (size,) = frames.HEADER.unpack(header)
        payload = bytearray()
        while len(payload) < size:
            payload += stream.read(size - len(payload))
        captured.append(bytes(payload))
        return frames.parse_payload(bytes(payload))

    frames.read_frame = capturing_read_frame
    try:
        with ChildClient((ROOT / "submissions" / "gymnasium_complete.py").resolve()) as client:
            frame = client.call(function, *args)
    finally:
        frames.read_frame = read_frame
    if frame is None or frame["status"] != "ok":
        raise RuntimeError(f"{function}{args} did not return: {frame and frame['message']}")
    return captured[-1]


def forged_frame(megabytes: int) -> bytes:
    """What submissions/hostile/forged_big_frame.py writes (id and nonce as the harness would send)."""
    value = "[" + ",".join(["{}"] * (megabytes * (1 << 20) // 3)) + "]"
    nonce = "0" * 32
    return (
        f'{{"type":"result","id":0,"nonce":"{nonce}","status":"ok","value":{value},"message":"",'
        '"traceback":"","episodes":[],"compat_events":[],"wall_time":0.1}'
    ).encode()


def _run(mode: str, path: Path, budget: list[int] | None, trace: bool) -> dict[str, object]:
    command = [sys.executable, "-c", MEASURE.format(root=str(ROOT)), mode, str(path), json.dumps(budget)]
    output = subprocess.run(
        [*command, "trace" if trace else "time"], check=True, capture_output=True, text=True
    ).stdout
    return json.loads(output)  # type: ignore[no-any-return]


def measure(mode: str, path: Path, budget: list[int] | None, repetitions: int) -> dict[str, object]:
    """Median wall time over `repetitions` runs, and the peak traced memory of one more run."""
    runs = [_run(mode, path, budget, trace=False) for _ in range(repetitions)]
    traced = _run(mode, path, budget, trace=True)
    return {
        "seconds": statistics.median(float(run["seconds"]) for run in runs),  # type: ignore[arg-type]
        "peak_mib": traced["peak_mib"],
        "verdict": traced["verdict"],
    }


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--repetitions", type=int, default=3)
    arguments = parser.parse_args()
    from reference.oracles.taxi import optimal_q_table

    q_table = optimal_q_table(0.6).tolist()
    frames = {
        "honest taxi(q_table)": (honest_frame("taxi", (q_table,)), [20_200, 2_500_000]),
        "honest blackjack(13)": (honest_frame("blackjack", (13,)), [10_100, 40_000]),
        "forged 24 MB [{},...], no budget": (forged_frame(24), None),
        "forged 24 MB [{},...], budget 4 x 1000": (forged_frame(24), [4, 1000]),
    }
    print("| frame | size | budget | before: time | before: peak | after: time | after: peak | after |")
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as directory:
        for name, (payload, budget) in frames.items():
            path = Path(directory) / "frame.json"
            path.write_bytes(payload)
            before = measure("before", path, budget, arguments.repetitions)
            after = measure("after", path, budget, arguments.repetitions)
            shown = "none" if budget is None else f"{budget[0]:,} episodes, {budget[1]:,} steps"
            print(
                f"| {name} | {len(payload) / 1e6:.1f} MB | {shown} | {before['seconds']:.2f} s | "
                f"{before['peak_mib']:.0f} MiB | {after['seconds']:.3f} s | {after['peak_mib']:.0f} MiB | "
                f"{after['verdict']} |"
            )


if __name__ == "__main__":
    main()
