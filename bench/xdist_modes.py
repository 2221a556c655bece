"""Makespan of one grading session under xdist's stock schedulers and under `LongestFirstScheduling`.

`--dist load --maxschedchunk 1` and `--dist worksteal` (xdist's own scheduler classes) against
`grader.grading.scheduling.LongestFirstScheduling` (one real item per worker, a slot after each), driven by
simulated workers that behave as xdist's do (`xdist/remote.py`): a worker starts an item only once it holds
the next one or the shutdown, and a steal takes only items queued behind that next one. The cases are
sorted longest first, as the plugin sorts them; each lasts its problem's `expected_seconds` (an idealisation:
the real durations vary, and `find_qvalues` is skipped by default at almost no cost). Deterministic.

    python bench/xdist_modes.py [--workers 2] [--files 1,24]
"""

from __future__ import annotations

import argparse
import heapq
import sys
import tomllib
from pathlib import Path

from xdist.scheduler.load import LoadScheduling
from xdist.scheduler.worksteal import WorkStealingScheduling

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from grader.grading.scheduling import SLOT_SUFFIX, LongestFirstScheduling  # noqa: E402

SHUTDOWN = object()


class Gateway:
    def __init__(self, name: str) -> None:
        self.id = name


STEALS: list[tuple[Node, list[int]]] = []


class Node:
    def __init__(self, name: str) -> None:
        self.gateway = Gateway(name)
        self.torun: list[object] = []
        self.shutting_down = False
        self.busy = False

    def send_runtest_some(self, indices: list[int]) -> None:
        self.torun.extend(indices)

    def send_steal(self, indices: list[int]) -> None:
        queued = [
            index for index in self.torun[1:] if index is not SHUTDOWN
        ]  # torun[0] is the held next item
        stolen = list(indices) if set(indices) <= set(queued) else []
        self.torun = [index for index in self.torun if index not in stolen]
        STEALS.append((self, stolen))

    def shutdown(self) -> None:
        if not self.shutting_down:
            self.shutting_down = True
            self.torun.append(SHUTDOWN)


def load_scheduler(workers: int) -> LoadScheduling:
    scheduler = LoadScheduling.__new__(LoadScheduling)
    scheduler.numnodes = workers
    scheduler.node2collection, scheduler.node2pending, scheduler.pending = {}, {}, []
    scheduler.collection = None
    scheduler.log = lambda *args: None
    scheduler.maxschedchunk = 1
    return scheduler


def worksteal_scheduler(workers: int) -> WorkStealingScheduling:
    scheduler = WorkStealingScheduling.__new__(WorkStealingScheduling)
    scheduler.numnodes = workers
    scheduler.node2collection, scheduler.node2pending, scheduler.pending = {}, {}, []
    scheduler.collection = None
    scheduler.log = lambda *args: None
    scheduler.steal_requested_from_node = None
    return scheduler


def simulate(durations: list[float], workers: int, mode: str) -> tuple[float, list[float]]:
    """The makespan, and each real item's waiting time between the session start and its own start."""
    if mode == "longest-first":
        collection = [
            name for index in range(len(durations)) for name in (f"c{index}", f"c{index}{SLOT_SUFFIX}")
        ]
        scheduler = LongestFirstScheduling(workers)
        cost = [duration for duration in durations for duration in (duration, 0.0)]
    else:
        collection = [f"c{index}" for index in range(len(durations))]
        scheduler = load_scheduler(workers) if mode == "load" else worksteal_scheduler(workers)
        cost = list(durations)
    nodes = [Node(f"gw{index}") for index in range(workers)]
    for node in nodes:
        scheduler.add_node(node)  # type: ignore[arg-type]
        scheduler.add_node_collection(node, collection)  # type: ignore[arg-type]
    scheduler.schedule()

    def answer_steals() -> None:
        while STEALS:
            node, stolen = STEALS.pop(0)
            scheduler.remove_pending_tests_from_node(node, stolen)  # type: ignore[arg-type]

    answer_steals()
    events: list[tuple[float, int, int]] = []
    started: dict[int, float] = {}
    now = 0.0

    def start(node_index: int) -> None:
        node = nodes[node_index]
        if node.busy or not node.torun or node.torun[0] is SHUTDOWN:
            return
        if len(node.torun) < 2:
            return  # xdist's worker waits for its next item (or the shutdown) before it starts one
        index = node.torun.pop(0)
        assert isinstance(index, int)
        node.busy = True
        started[index] = now
        heapq.heappush(events, (now + cost[index], node_index, index))

    for node_index in range(workers):
        start(node_index)
    while events:
        now, node_index, index = heapq.heappop(events)
        nodes[node_index].busy = False
        scheduler.mark_test_complete(nodes[node_index], index, cost[index])  # type: ignore[arg-type]
        answer_steals()
        for other in range(workers):
            start(other)
    real = [i for i in range(len(collection)) if not collection[i].endswith(SLOT_SUFFIX)]
    assert all(i in started for i in real), "an item never started"
    return now, [started[i] for i in real]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--files", default="1,24")
    args = parser.parse_args()
    configs = {"classic": ROOT / "grader/lab/assignment.toml", "rl1": ROOT / "grader/lab/editions/rl1.toml"}
    print("| edition | files | workers | bound | longest-first | load, --maxschedchunk 1 | worksteal |")
    print("|---|---|---|---|---|---|---|")
    for edition, path in configs.items():
        problems = tomllib.loads(path.read_text(encoding="utf-8"))["problems"]
        expected = sorted(
            (table["expected_seconds"] for table in problems.values() if table.get("enabled", True)),
            reverse=True,
        )
        for files in (int(n) for n in args.files.split(",")):
            durations = sorted(expected * files, reverse=True)  # the plugin sorts the cases longest first
            bound = max(durations[0], sum(durations) / args.workers)
            ours, _ = simulate(durations, args.workers, "longest-first")
            load, _ = simulate(durations, args.workers, "load")
            steal, _ = simulate(durations, args.workers, "worksteal")
            print(
                f"| {edition} | {files} | {args.workers} | {bound:.0f} s | {ours:.0f} s | {load:.0f} s "
                f"({load / ours:.2f}x) | {steal:.0f} s ({steal / ours:.2f}x) |"
            )


if __name__ == "__main__":
    main()
