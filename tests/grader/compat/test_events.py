"""Tests for grader.compat.events: recorded once per kind and env, counted, cleared by drain."""

from __future__ import annotations

import pytest

from grader.compat import events
from grader.compat.events import CompatEvent


@pytest.fixture(autouse=True)
def _empty_log() -> None:
    events.drain()


def test_drain_returns_events_in_first_occurrence_order_and_clears_them() -> None:
    events.record(events.RENAMED_ID, "Taxi-v3", "renamed")
    events.record(events.NUMPY_ACTION, "Taxi-v3", "numpy")
    assert events.drain() == [
        CompatEvent(events.RENAMED_ID, "Taxi-v3", "renamed"),
        CompatEvent(events.NUMPY_ACTION, "Taxi-v3", "numpy"),
    ]
    assert events.drain() == []


def test_repeats_are_counted_not_stored() -> None:
    for _ in range(1000):
        events.record(events.NUMPY_ACTION, "Taxi-v3", "numpy")
    events.record(events.NUMPY_ACTION, "Blackjack-v0", "numpy")
    assert events.drain() == [
        CompatEvent(events.NUMPY_ACTION, "Taxi-v3", "numpy (1000 times)"),
        CompatEvent(events.NUMPY_ACTION, "Blackjack-v0", "numpy"),
    ]


def test_an_unknown_kind_is_refused() -> None:
    with pytest.raises(ValueError, match="unknown compat event kind 'oops'"):
        events.record("oops", "Taxi-v3", "detail")
