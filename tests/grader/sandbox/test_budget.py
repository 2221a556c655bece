"""Result-frame limits derived from a call's budget (grader/sandbox/child/budget.py)."""

from __future__ import annotations

import json

import pytest

from grader.sandbox.child.budget import (
    EPISODE_BYTES,
    EPISODE_NODES,
    FRAME_ALLOWANCE_BYTES,
    FRAME_ALLOWANCE_NODES,
    LIST_STEPS,
    STEP_BYTES,
    STEP_NODES,
    UNBUDGETED_NODES,
    FrameLimits,
    WireBudget,
    frame_limits,
    structural_count,
)
from grader.sandbox.child.frames import MAX_NODES

MAX_FRAME = 256 << 20


@pytest.mark.parametrize(
    ("budget", "record", "expected"),
    [
        (
            WireBudget(4, 1000),
            True,
            FrameLimits(
                FRAME_ALLOWANCE_BYTES + 4 * EPISODE_BYTES + 1000 * STEP_BYTES,
                FRAME_ALLOWANCE_NODES + 4 * EPISODE_NODES + 1000 * STEP_NODES,
            ),
        ),
        (
            WireBudget(20_000, 5_000_000),
            True,
            FrameLimits(MAX_FRAME, FRAME_ALLOWANCE_NODES + 20_000 * EPISODE_NODES + LIST_STEPS * STEP_NODES),
        ),
        (None, True, FrameLimits(MAX_FRAME, UNBUDGETED_NODES)),
        (WireBudget(4, 1000), False, FrameLimits(MAX_FRAME, MAX_NODES + FRAME_ALLOWANCE_NODES)),
    ],
    ids=["small-budget", "large-budget-capped", "no-budget", "not-recording"],
)
def test_frame_limits_follow_the_budget(
    budget: WireBudget | None, record: bool, expected: FrameLimits
) -> None:
    assert frame_limits(budget, record=record, max_frame=MAX_FRAME) == expected


@pytest.mark.parametrize(
    "value",
    [[], [{}, {}, []], {"a": [1, 2, {"b": "x,y[{"}]}, "plain", [[[[1]]]]],
    ids=["empty", "empty-containers", "commas-in-strings", "scalar", "nested"],
)
def test_the_structural_count_bounds_the_values_json_builds(value: object) -> None:
    def values(node: object) -> int:
        if isinstance(node, list):
            return 1 + sum(map(values, node))
        if isinstance(node, dict):
            return 1 + sum(map(values, node.values()))
        return 1

    assert structural_count(json.dumps(value).encode()) >= values(value)


def test_a_frame_over_either_limit_is_named_without_parsing() -> None:
    limits = FrameLimits(max_bytes=100, max_nodes=20)

    assert limits.excess(b"[" + b"{}," * 5 + b"{}]") == ""
    assert limits.excess(b"x" * 101) == "a result frame of 101 bytes exceeds this call's limit of 100 bytes"
    assert limits.excess(b"[" + b"{}," * 20 + b"{}]") == (
        "a result frame with 43 elements exceeds this call's limit of 20 elements"
    )


@pytest.mark.parametrize(
    "data",
    [
        {"max_episodes": -1, "max_steps": 3},
        {"max_episodes": 1},
        [1, 2],
        {"max_episodes": True, "max_steps": 3},
    ],
    ids=["negative", "missing", "list", "bool"],
)
def test_malformed_budgets_are_refused(data: object) -> None:
    with pytest.raises(ValueError, match="a budget must be null or two non-negative ints"):
        WireBudget.from_plain(data)
