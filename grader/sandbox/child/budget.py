"""A call's recording budget on the wire, and the result-frame limits both sides derive from it.

The parent refuses a result frame beyond these limits before building any Python object from it (a
forged frame costs the grader at most what an honest one may); the child checks its own frame against
the same limits, so an honest result that would not fit ends as `output_too_large` instead. The
constants are upper bounds on what `grader.sandbox.child.recorder` encodes, measured on the lab's
envs with margin (bench/frames.py, bench/RESULTS.md "Bounded frames").
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from grader.sandbox.child.frames import MAX_NODES

FRAME_ALLOWANCE_BYTES = 4 << 20
"""Bytes of a result frame besides its episodes: return value, message, traceback, compat events."""
FRAME_ALLOWANCE_NODES = 500_000
"""Structural characters (`,` `[` `{`) of a result frame besides its episodes."""
EPISODE_BYTES = 1024
"""Bytes of one encoded episode besides its steps (in the columnar block a few in the per-episode arrays,
plus its env's table entry and reset options where it has them: a few hundred)."""
EPISODE_NODES = 64
"""Structural characters of one encoded episode besides its steps (none in the per-episode arrays; about
10 for a table entry or reset options, plus their contents)."""
STEP_BYTES = 64
"""Bytes of one step: about 6 in the block's arrays (int8 action and reward, two flags, base64); an action
sent in the plain form takes up to about 62 (a tagged array)."""
STEP_NODES = 8
"""Structural characters of one step whose action travels in the plain form (an array action: about 7)."""
LIST_STEPS = MAX_NODES // 2 // 4
"""Most steps whose structural characters the limit counts: beyond them a log's actions are arrays, whose
steps add none (`encode_value` refuses a plain form of more than `MAX_NODES` elements anyway)."""
UNBUDGETED_NODES = 4 * MAX_NODES
"""Structural characters of a recording call without a budget (a 120 000-episode Taxi log has 4 million)."""


@dataclass(frozen=True)
class WireBudget:
    """`grader.sandbox.limits.CallBudget` as the child receives it in a call frame."""

    max_episodes: int
    max_steps: int

    def to_plain(self) -> dict[str, int]:
        """The `budget` field of a call frame."""
        return {"max_episodes": self.max_episodes, "max_steps": self.max_steps}

    @classmethod
    def from_plain(cls, data: Any) -> WireBudget | None:
        """The budget of a call frame's `budget` field (None for null).

        Raises:
            ValueError: the field is neither null nor {"max_episodes": int >= 0, "max_steps": int >= 0}.
        """
        if data is None:
            return None
        if (
            type(data) is not dict
            or data.keys() != {"max_episodes", "max_steps"}
            or not all(type(value) is int and value >= 0 for value in data.values())
        ):
            raise ValueError(f"a budget must be null or two non-negative ints, found {str(data)[:80]}")
        return cls(data["max_episodes"], data["max_steps"])


@dataclass(frozen=True)
class FrameLimits:
    """The largest result frame of one call: its bytes and its structural characters."""

    max_bytes: int
    max_nodes: int

    def excess(self, payload: bytes) -> str:
        """Why `payload` exceeds these limits, or "" when it does not (counted without parsing it)."""
        if len(payload) > self.max_bytes:
            return f"a result frame of {len(payload):,} bytes exceeds this call's limit of {self.max_bytes:,} bytes"  # noqa: E501
        nodes = structural_count(payload)
        if nodes > self.max_nodes:
            return f"a result frame with {nodes:,} elements exceeds this call's limit of {self.max_nodes:,} elements"  # noqa: E501
        return ""


def structural_count(payload: bytes) -> int:
    """An upper bound on the JSON values in `payload`: one more than its `,` `[` and `{` (C-speed counts).

    Every value but the first of a container follows a comma, and the first follows its `[` or `{`;
    counting the characters inside strings too only raises the bound.
    """
    return 1 + payload.count(b",") + payload.count(b"[") + payload.count(b"{")


def frame_limits(budget: WireBudget | None, *, record: bool, max_frame: int) -> FrameLimits:
    """The limits of one call's result frame.

    Args:
        budget: The call's budget (None: the sandbox-wide limits).
        record: Whether the call records episodes (without, the frame carries only the return value,
            bounded as `encode_value` bounds it).
        max_frame: The sandbox's largest frame (`Limits.frame_bytes`), never exceeded.

    Returns:
        bytes = allowance + episodes x EPISODE_BYTES + steps x STEP_BYTES and
        nodes = allowance + episodes x EPISODE_NODES + min(steps, LIST_STEPS) x STEP_NODES,
        each at most the sandbox-wide limit.
    """
    if not record:  # the return value alone, as `encode_value` bounds it
        return FrameLimits(max_frame, MAX_NODES + FRAME_ALLOWANCE_NODES)
    if budget is None:
        return FrameLimits(max_frame, UNBUDGETED_NODES)
    size = FRAME_ALLOWANCE_BYTES + budget.max_episodes * EPISODE_BYTES + budget.max_steps * STEP_BYTES
    nodes = (
        FRAME_ALLOWANCE_NODES
        + budget.max_episodes * EPISODE_NODES
        + min(budget.max_steps, LIST_STEPS) * STEP_NODES
    )
    return FrameLimits(min(size, max_frame), min(nodes, UNBUDGETED_NODES))
