"""Tests of grader/grading/scheduling.py: one acceptance item per worker at a time, longest first."""

from __future__ import annotations

import heapq
from dataclasses import dataclass, field

import pytest

from grader.grading.scheduling import SLOT_SUFFIX, LongestFirstScheduling


@dataclass(eq=False)
class FakeGateway:
    id: str


@dataclass(eq=False)
class FakeNode:
    """Stands in for xdist's WorkerController: records what the scheduler sent."""

    name: str
    sent: list[int] = field(default_factory=list)
    shut_down: bool = False

    @property
    def gateway(self) -> FakeGateway:
        return FakeGateway(self.name)

    def send_runtest_some(self, indices: list[int]) -> None:
        self.sent += indices

    def shutdown(self) -> None:
        self.shut_down = True


def _collection(names: list[str]) -> list[str]:
    collection = []
    for name in names:
        collection += [
            f"test_{name}.py::test_{name}[0:a.py]",
            f"test_{name}.py::test_{name}[0:a.py]{SLOT_SUFFIX}",
        ]
    return collection


def _scheduler(nodes: list[FakeNode], collection: list[str]) -> LongestFirstScheduling:
    scheduler = LongestFirstScheduling(len(nodes))
    for node in nodes:
        scheduler.add_node(node)  # type: ignore[arg-type]
        scheduler.add_node_collection(node, collection)  # type: ignore[arg-type]
    scheduler.schedule()
    return scheduler


def test_each_worker_gets_one_item_and_its_slot() -> None:
    nodes = [FakeNode("gw0"), FakeNode("gw1")]
    scheduler = _scheduler(nodes, _collection(["taxi", "car", "cartpole", "blackjack"]))
    assert [node.sent for node in nodes] == [[0, 1], [2, 3]]
    scheduler.mark_test_complete(nodes[1], 2)  # type: ignore[arg-type]
    assert nodes[1].sent == [2, 3, 4, 5]
    scheduler.mark_test_complete(nodes[1], 3)  # type: ignore[arg-type]
    assert nodes[1].sent == [2, 3, 4, 5], "finishing a slot must not hand out more work"


def test_workers_shut_down_when_the_queue_is_empty() -> None:
    nodes = [FakeNode("gw0"), FakeNode("gw1"), FakeNode("gw2")]
    scheduler = _scheduler(nodes, _collection(["taxi", "car"]))
    assert nodes[2].shut_down and nodes[2].sent == []
    assert not scheduler.tests_finished
    for node, item in ((nodes[0], 0), (nodes[1], 2)):
        scheduler.mark_test_complete(node, item)  # type: ignore[arg-type]
    assert all(node.shut_down for node in nodes)
    assert scheduler.tests_finished


def test_a_crashed_worker_names_its_item_and_requeues_the_rest() -> None:
    nodes = [FakeNode("gw0"), FakeNode("gw1")]
    collection = _collection(["taxi", "car", "cartpole"])
    scheduler = _scheduler(nodes, collection)
    crashed = scheduler.remove_node(nodes[0])  # type: ignore[arg-type]
    assert crashed == collection[0]
    scheduler.mark_test_complete(nodes[1], 2)  # type: ignore[arg-type]
    assert nodes[1].sent == [2, 3, 4, 5]


def _simulate(durations: list[float], workers: int) -> float:
    """Run the scheduler against simulated workers; return the makespan."""
    nodes = [FakeNode(f"gw{index}") for index in range(workers)]
    scheduler = _scheduler(nodes, _collection([f"p{index}" for index in range(len(durations))]))
    events: list[tuple[float, int, int]] = []
    started: dict[int, int] = {}

    def start_next(node_index: int, now: float) -> None:
        node = nodes[node_index]
        real = [index for index in node.sent if index % 2 == 0 and index not in started]
        if real:
            started[real[0]] = node_index
            heapq.heappush(events, (now + durations[real[0] // 2], node_index, real[0]))

    for node_index in range(workers):
        start_next(node_index, 0.0)
    now = 0.0
    while events:
        now, node_index, item = heapq.heappop(events)
        scheduler.mark_test_complete(nodes[node_index], item)  # type: ignore[arg-type]
        start_next(node_index, now)
    assert len(started) == len(durations)
    return now


@pytest.mark.parametrize(
    ("durations", "workers", "makespan"),
    [
        ([40.0, 8.0, 6.0, 6.0, 4.0, 1.0], 2, 40.0),
        ([60.0, 10.0, 8.0, 8.0, 6.0, 2.0], 2, 60.0),
        ([5.0, 4.0, 3.0, 3.0, 2.0, 1.0], 2, 9.0),
        ([5.0, 4.0, 3.0, 3.0, 2.0, 1.0], 3, 6.0),
    ],
    ids=["one-long-check", "taxi-trains", "balanced-2", "balanced-3"],
)
def test_longest_first_reaches_the_list_scheduling_makespan(
    durations: list[float], workers: int, makespan: float
) -> None:
    assert _simulate(durations, workers) == pytest.approx(makespan)
