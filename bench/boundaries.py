"""What validating a result frame costs with declared models against the hand-written checks (issue 11).

Frames measured, recorded by the real child harness from submissions/gymnasium_complete.py (through
bench/frames.py): `cartpole()` (one episode), `blackjack(13)` (10 000 games, list columns),
`taxi(q_table)` (20 000 episodes: 10 000 random ones of up to 200 steps as arrays, 10 000 greedy ones as
lists) and the first 100 episodes of that Taxi frame. Each frame is handled in a fresh subprocess, the way
the runner handles a result frame, with the call's budget:

  * old: `parse_payload`, the hand checks of the frame (`runner._frame_problem`) and of the episodes
    (`episode_log.episodes_from_plain`), both as of OLD_REVISION (read with `git show`);
  * new: `parse_payload`, `messages.result_message` and `episode_log.episodes_from_plain` (`WireEpisode`).

Old and new alternate; wall time is the least of `--repetitions` runs; peak memory is tracemalloc's peak
of one more run (tracing slows parsing). With msgspec installed, the validation of the episodes'
structure alone (no array decoding) is also timed with msgspec Structs against the pydantic model, the
choice this bench informed. Captured frames are kept in `--frames DIR` (default: a temporary directory).

    python bench/boundaries.py [--repetitions 5] [--frames /tmp/frames]
"""

from __future__ import annotations

import argparse
import ast
import json
import subprocess
import sys
import tempfile
import time
import tracemalloc
import types
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

OLD_REVISION = "0307379"
"""The commit before issue 11's declared boundaries (the hand-written checks)."""
FRAMES = ("cartpole()", "blackjack(13)", "taxi(q_table), 100 episodes", "taxi(q_table)")


def capture(directory: Path) -> dict[str, Path]:
    """Record the frames (once per directory) and return their paths."""
    paths = {name: directory / f"{index}.json" for index, name in enumerate(FRAMES)}
    if all(path.exists() for path in paths.values()):
        return paths
    sys.path.insert(0, str(ROOT / "bench"))
    from frames import honest_frame

    from reference.oracles.taxi import optimal_q_table

    paths["cartpole()"].write_bytes(honest_frame("cartpole", ()))
    paths["blackjack(13)"].write_bytes(honest_frame("blackjack", (13,)))
    taxi = honest_frame("taxi", (optimal_q_table(0.6).tolist(),))
    paths["taxi(q_table)"].write_bytes(taxi)
    frame = json.loads(taxi)
    frame["episodes"] = frame["episodes"][:100]
    paths["taxi(q_table), 100 episodes"].write_bytes(json.dumps(frame, separators=(",", ":")).encode())
    return paths


def budget_of(name: str) -> tuple[int, int]:
    """The budget the checks give the call (grader.checks.integrity.games_budget)."""
    from grader.checks.integrity import games_budget

    games = {"cartpole()": (1, 1_000), "blackjack(13)": (10_000, 16)}.get(name, (20_000, 250))
    budget = games_budget(*games)
    return budget.max_episodes, budget.max_steps


def old_checks() -> tuple[Any, Any]:
    """`_frame_problem` and `episodes_from_plain` as of OLD_REVISION."""
    episode_log = types.ModuleType("old_episode_log")
    sys.modules[episode_log.__name__] = episode_log  # its dataclass looks itself up there
    source = _git_show("grader/sandbox/episode_log.py")
    exec(compile(source, "old_episode_log.py", "exec"), episode_log.__dict__)
    runner = ast.parse(_git_show("grader/sandbox/runner.py"))
    wanted = {"_CHILD_STATUSES", "_RESULT_FIELDS", "_frame_problem"}
    nodes = [node for node in runner.body if _names(node) & wanted]
    from grader.sandbox.outcome import OutcomeStatus

    namespace: dict[str, Any] = {"OutcomeStatus": OutcomeStatus, "Any": Any}
    exec(compile(ast.Module(nodes, []), "old_runner.py", "exec"), namespace)
    return namespace["_frame_problem"], episode_log.episodes_from_plain


def _git_show(path: str) -> str:
    return subprocess.run(
        ["git", "show", f"{OLD_REVISION}:{path}"], cwd=ROOT, check=True, capture_output=True, text=True
    ).stdout


def _names(node: ast.stmt) -> set[str]:
    if isinstance(node, ast.FunctionDef):
        return {node.name}
    if isinstance(node, ast.Assign):
        return {target.id for target in node.targets if isinstance(target, ast.Name)}
    return set()


def handle(mode: str, payload: bytes, budget: tuple[int, int]) -> int:
    """Handle one result frame as the runner does; returns the number of episodes decoded."""
    from grader.sandbox.child.frames import parse_payload
    from grader.sandbox.limits import CallBudget

    call_budget = CallBudget(*budget)
    frame = parse_payload(payload)
    if mode == "old":
        frame_problem, episodes_from_plain = old_checks.cached  # type: ignore[attr-defined]
        problem = frame_problem(frame, frame["id"], frame["nonce"])
        if problem:
            raise RuntimeError(problem)
        return len(episodes_from_plain(frame["episodes"], call_budget))
    from grader.sandbox.episode_log import episodes_from_plain
    from grader.sandbox.messages import result_message

    message = result_message(frame)
    if isinstance(message, str):
        raise RuntimeError(message)
    return len(episodes_from_plain(message.episodes, call_budget))


def measure_once(mode: str, path: Path, budget: tuple[int, int], trace: bool) -> dict[str, Any]:
    """One handling in this process: seconds, traced peak MiB (when tracing), episodes decoded."""
    payload = path.read_bytes()
    if mode == "old":
        old_checks.cached = old_checks()  # type: ignore[attr-defined]
    from grader.sandbox import episode_log, messages  # imports are not what is measured

    del episode_log, messages

    if trace:
        tracemalloc.start()
    started = time.perf_counter()
    episodes = handle(mode, payload, budget)
    seconds = time.perf_counter() - started
    peak = tracemalloc.get_traced_memory()[1] / (1 << 20) if trace else 0.0
    return {"seconds": seconds, "peak_mib": peak, "episodes": episodes}


def run(mode: str, path: Path, budget: tuple[int, int], trace: bool) -> dict[str, Any]:
    """`measure_once` in a fresh subprocess."""
    command = [sys.executable, __file__, "--measure", mode, str(path), json.dumps(budget)]
    output = subprocess.run(
        [*command, "trace" if trace else "time"], check=True, capture_output=True, text=True
    ).stdout
    return json.loads(output)  # type: ignore[no-any-return]


def compare(path: Path, budget: tuple[int, int], repetitions: int) -> dict[str, dict[str, Any]]:
    """Old and new alternated `repetitions` times (the least time of each: the machine's load only adds),
    then the traced peak of one more run of each."""
    times: dict[str, list[float]] = {"old": [], "new": []}
    for _ in range(repetitions):
        for mode, seconds in times.items():
            seconds.append(run(mode, path, budget, trace=False)["seconds"])
    return {
        mode: {**run(mode, path, budget, trace=True), "seconds": min(seconds)}
        for mode, seconds in times.items()
    }


def structure_only(paths: dict[str, Path], repetitions: int) -> list[str]:
    """Validating the episodes' structure (no array decoded): pydantic `WireEpisode` against msgspec."""
    if msgspec is None:
        return ["(msgspec is not installed: `pip install msgspec` to compare it)"]
    from grader.sandbox.child.frames import parse_payload, paused_gc
    from grader.sandbox.episode_log import WIRE_EPISODES

    def best(function: Any, data: Any) -> float:
        times = []
        for _ in range(repetitions):
            with paused_gc():
                started = time.perf_counter()
                function(data)
                times.append(time.perf_counter() - started)
        return min(times)

    lines = ["| frame | pydantic WireEpisode | msgspec Struct |", "|---|---|---|"]
    for name, path in paths.items():
        episodes = parse_payload(path.read_bytes())["episodes"]
        pydantic_seconds = best(WIRE_EPISODES.validate_python, episodes)
        msgspec_seconds = best(
            lambda data: msgspec.convert(data, list[MsgspecEpisode], strict=True), episodes
        )
        lines.append(f"| {name} | {pydantic_seconds * 1e3:.1f} ms | {msgspec_seconds * 1e3:.1f} ms |")
    return lines


try:
    import msgspec
except ImportError:  # the comparison is optional; msgspec is not a dependency
    msgspec = None
else:

    class MsgspecArraySpec(msgspec.Struct, forbid_unknown_fields=True):
        dtype: str
        shape: list[int]
        data: str

    class MsgspecTaggedArray(msgspec.Struct, forbid_unknown_fields=True):
        spec: MsgspecArraySpec = msgspec.field(name="$ndarray")

    class MsgspecNonFinite(msgspec.Struct, forbid_unknown_fields=True):
        tag: str = msgspec.field(name="$float")

    class MsgspecEpisode(msgspec.Struct, forbid_unknown_fields=True):
        """`WireEpisode` as msgspec Structs (the same structure, without the bounds and cleaning)."""

        env_index: int
        requested_id: str
        env_id: str
        env_kwargs: dict[str, Any]
        reset_seed: int
        student_seed: int | None
        reset_options: dict[str, Any] | None
        actions: list[Any] | MsgspecTaggedArray
        rewards: list[float | MsgspecNonFinite] | MsgspecTaggedArray
        terminated: list[bool] | MsgspecTaggedArray
        truncated: list[bool] | MsgspecTaggedArray


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--repetitions", type=int, default=5)
    parser.add_argument("--frames", type=Path, default=None)
    parser.add_argument("--measure", nargs=4, help=argparse.SUPPRESS)
    parser.add_argument("--structure-only", action="store_true", help="only the pydantic/msgspec table")
    arguments = parser.parse_args()
    if arguments.measure:
        mode, path, budget, trace = arguments.measure
        print(json.dumps(measure_once(mode, Path(path), tuple(json.loads(budget)), trace == "trace")))
        return
    with tempfile.TemporaryDirectory() as temporary:
        directory = arguments.frames or Path(temporary)
        directory.mkdir(parents=True, exist_ok=True)
        paths = capture(directory)
        if arguments.structure_only:
            print("\n".join(structure_only(paths, arguments.repetitions)))
            return
        print("| frame | size | episodes | old: time | old: peak | new: time | new: peak | new / old |")
        print("|---|---|---|---|---|---|---|---|")
        for name, path in paths.items():
            budget = budget_of(name)
            result = compare(path, budget, arguments.repetitions)
            old, new = result["old"], result["new"]
            print(
                f"| {name} | {path.stat().st_size / 1e6:.2f} MB | {new['episodes']:,} | "
                f"{old['seconds'] * 1e3:.1f} ms | {old['peak_mib']:.0f} MiB | "
                f"{new['seconds'] * 1e3:.1f} ms | {new['peak_mib']:.0f} MiB | "
                f"{new['seconds'] / old['seconds']:.2f} |"
            )
        print()
        print("\n".join(structure_only(paths, arguments.repetitions)))


if __name__ == "__main__":
    main()
