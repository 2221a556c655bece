"""What the compatibility layer had to tolerate, recorded as `CompatEvent`s until drained."""

from __future__ import annotations

from dataclasses import dataclass

STEP_BEFORE_RESET = "step_before_reset"
STEP_AFTER_DONE = "step_after_done"
NUMPY_ACTION = "numpy_action"
RENDER_WITHOUT_MODE = "render_without_mode"
LEGACY_SEED_CALL = "legacy_seed_call"
RENAMED_ID = "renamed_id"
SEED_REPLACED = "seed_replaced"
API_DETECTED = "api_detected"
WRAPPER_ATTRIBUTE = "wrapper_attribute"
"""An attribute of the env inside gymnasium's wrappers read on the outer env (`env.P`): gymnasium 1.x no
longer forwards such reads, gym and gymnasium before 1.0 did, and the second lab's texts rely on it."""
ENV_OBJECT_PASSED = "env_object"
"""Not the lab's API but the grader's call: a function given an environment's name failed on it before
making or playing anything, so it was called again with an env object (`EnvArgument`'s `name_or_object`)."""
ENV_CLOSED = "env_closed"
"""Not a tolerance but a fact the second lab grades: a function closed an environment (`env.close()`);
its `run_simulation` is told not to close the env it is given."""

KINDS = (
    STEP_BEFORE_RESET,
    STEP_AFTER_DONE,
    NUMPY_ACTION,
    RENDER_WITHOUT_MODE,
    LEGACY_SEED_CALL,
    RENAMED_ID,
    SEED_REPLACED,
    API_DETECTED,
    WRAPPER_ATTRIBUTE,
    ENV_OBJECT_PASSED,
    ENV_CLOSED,
)


@dataclass(frozen=True)
class CompatEvent:
    """One thing classic gym allowed that gymnasium 1.4 refuses (or does differently).

    Attributes:
        kind: one of `KINDS`.
        env_id: the id the student asked for (`"Blackjack-v0"`).
        detail: a sentence a student can read; ends with "(N times)" when it happened N > 1 times.
    """

    kind: str
    env_id: str
    detail: str


# One entry per (kind, env_id), the first detail and how many times it happened: code that steps
# millions of times with numpy actions must not grow this without bound.
_pending: dict[tuple[str, str], tuple[str, int]] = {}
_drains = 0


def record(kind: str, env_id: str, detail: str) -> None:
    """Record that `kind` happened in an env made as `env_id`.

    Args:
        kind: one of `KINDS`.
        env_id: the id the student asked for.
        detail: what happened and what the layer did about it (kept from the first occurrence).

    Raises:
        ValueError: `kind` is not one of `KINDS`.
    """
    key = (kind, env_id)
    seen = _pending.get(key)
    if seen is not None:
        _pending[key] = (seen[0], seen[1] + 1)
        return
    if kind not in KINDS:
        raise ValueError(f"unknown compat event kind {kind!r}; expected one of {', '.join(KINDS)}")
    _pending[key] = (detail, 1)


def drain() -> list[CompatEvent]:
    """Return the events recorded since the last drain, in first-occurrence order, and forget them."""
    drained = [
        CompatEvent(kind=kind, env_id=env_id, detail=detail if count == 1 else f"{detail} ({count} times)")
        for (kind, env_id), (detail, count) in _pending.items()
    ]
    _pending.clear()
    global _drains
    _drains += 1
    return drained


def generation() -> int:
    """How many times the events were drained: what is reported once per drain re-records when it changes."""
    return _drains
