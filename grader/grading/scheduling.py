"""Longest-expected-first scheduling for pytest-xdist: one acceptance test per worker at a time.

An xdist worker only starts an item once it holds the next one (pytest needs ``nextitem`` for fixture
teardown), so the stock ``load`` scheduler keeps two real items on every worker, even with
``--maxschedchunk 1``: the second-longest check can end up queued behind the longest one. Here every
acceptance item is followed in the collection by a *slot*, an empty item that only serves as that
``nextitem``. A worker is handed one ``[item, slot]`` unit at a time, in collection order (which the plugin
sorts by expected duration, longest first) and gets the next unit when its real item completes. That is
greedy list scheduling, which keeps the grading time close to max(longest check, total work / workers).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence

import pytest
from xdist.remote import Producer
from xdist.report import report_collection_diff
from xdist.workermanage import WorkerController

SLOT_SUFFIX = "~slot"


class SlotItem(pytest.Item):
    """An empty test placed after each acceptance test so a worker can start it at once."""

    def runtest(self) -> None:
        """Nothing to do: the slot exists only to be the worker's ``nextitem``."""


def with_slots(items: Sequence[pytest.Item]) -> list[pytest.Item]:
    """The items with a slot after each one (run on xdist workers only)."""
    slotted: list[pytest.Item] = []
    for item in items:
        slotted.append(item)
        parent = item.parent if item.parent is not None else item.session
        slotted.append(SlotItem.from_parent(parent, name=item.name + SLOT_SUFFIX))
    return slotted


def is_slot(nodeid: str) -> bool:
    """Whether a collected node id is a slot rather than an acceptance test."""
    return nodeid.endswith(SLOT_SUFFIX)


class LongestFirstScheduling:
    """xdist scheduler handing each worker one ``[item, slot]`` unit at a time, in collection order.

    Follows xdist's ``Scheduling`` protocol (``xdist/scheduler/protocol.py``).
    """

    def __init__(self, numnodes: int, log: Producer | None = None) -> None:
        self.numnodes = numnodes
        self.node2collection: dict[WorkerController, list[str]] = {}
        self.node2pending: dict[WorkerController, list[int]] = {}
        self.collection: list[str] | None = None
        self.units: deque[list[int]] = deque()
        self.log = Producer("longestfirst") if log is None else log.longestfirst
        self._shut_down: set[WorkerController] = set()

    @property
    def nodes(self) -> list[WorkerController]:
        """All nodes the scheduler knows."""
        return list(self.node2pending)

    @property
    def collection_is_completed(self) -> bool:
        """Whether every initial node has reported its collection."""
        return len(self.node2collection) >= self.numnodes

    @property
    def tests_finished(self) -> bool:
        """Whether nothing is left to hand out and no node holds more than its last item."""
        if not self.collection_is_completed or self.collection is None or self.units:
            return False
        return all(len(pending) < 2 for pending in self.node2pending.values())

    @property
    def has_pending(self) -> bool:
        """Whether any item is waiting or running."""
        return bool(self.units) or any(self.node2pending.values())

    def add_node(self, node: WorkerController) -> None:
        """Register a worker that has started."""
        self.node2pending[node] = []

    def add_node_collection(self, node: WorkerController, collection: Sequence[str]) -> None:
        """Record a worker's collection (all must be identical)."""
        if self.collection is not None and list(collection) != self.collection:
            first = next(iter(self.node2collection))
            self.log(report_collection_diff(self.collection, collection, first.gateway.id, node.gateway.id))
            return
        self.node2collection[node] = list(collection)

    def mark_test_complete(self, node: WorkerController, item_index: int, duration: float = 0) -> None:
        """A worker finished an item: when it was a real one, hand that worker the next unit."""
        self.node2pending[node].remove(item_index)
        if self.collection is not None and not is_slot(self.collection[item_index]):
            self._feed(node)

    def mark_test_pending(self, item: str) -> None:
        """Put an item back at the front of the queue (used by rerun plugins)."""
        if self.collection is None:
            return
        self.units.appendleft(self._unit_at(self.collection.index(item)))
        self._feed_idle()

    def remove_pending_tests_from_node(self, node: WorkerController, indices: Sequence[int]) -> None:
        """Not used: this scheduler never steals work back."""
        raise NotImplementedError("LongestFirstScheduling never sends 'steal' commands")

    def remove_node(self, node: WorkerController) -> str | None:
        """Forget a node; when it crashed, requeue what it held and name the item it was running."""
        pending = self.node2pending.pop(node)
        self._shut_down.discard(node)
        if not pending or self.collection is None:
            return None
        crashed, rest = pending[0], pending[1:]
        for index in reversed(rest):
            if not is_slot(self.collection[index]):
                self.units.appendleft(self._unit_at(index))
        self._feed_idle()
        return self.collection[crashed]

    def schedule(self) -> None:
        """Start handing out units once every worker has collected."""
        if self.collection is not None:
            self._feed_idle()
            return
        collections = list(self.node2collection.values())
        if any(collection != collections[0] for collection in collections[1:]):
            self.log("**Different tests collected, aborting run**")
            return
        self.collection = collections[0]
        self.units.extend(self._units(self.collection))
        self._feed_idle()

    def _units(self, collection: Sequence[str]) -> list[list[int]]:
        units: list[list[int]] = []
        current: list[int] = []
        for index, nodeid in enumerate(collection):
            current.append(index)
            if is_slot(nodeid):
                units.append(current)
                current = []
        if current:
            units.append(current)
        return units

    def _unit_at(self, index: int) -> list[int]:
        if (
            self.collection is not None
            and index + 1 < len(self.collection)
            and is_slot(self.collection[index + 1])
        ):
            return [index, index + 1]
        return [index]

    def _feed_idle(self) -> None:
        if self.collection is None:
            return
        for node, pending in list(self.node2pending.items()):
            if not any(not is_slot(self.collection[index]) for index in pending):
                self._feed(node)

    def _feed(self, node: WorkerController) -> None:
        if node in self._shut_down:
            return
        if not self.units:
            self._shut_down.add(node)
            node.shutdown()
            return
        unit = self.units.popleft()
        self.node2pending[node].extend(unit)
        node.send_runtest_some(unit)
        if self.collection is not None and not is_slot(self.collection[unit[-1]]):
            # Without a trailing slot the worker waits for a successor before it starts: give it one.
            self._feed(node)
