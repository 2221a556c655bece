"""The fields of an episode on the wire, declared once for the child's recorder and the parent's decoder.

Standard library only (the child imports it before the student's code, the parent without the child's
gymnasium set-up). The child's `EpisodeRecord.to_plain` sends exactly these keys in this order; the
parent's `grader.sandbox.episode_log.WireEpisode` validates exactly these keys and refuses to import if its
declaration drifts from them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

EPISODE_HEADER = (
    "env_index",
    "requested_id",
    "env_id",
    "env_kwargs",
    "reset_seed",
    "student_seed",
    "reset_options",
)
"""The fields of an episode besides its per-step columns, in the order they are sent."""
EPISODE_COLUMNS = ("actions", "rewards", "terminated", "truncated")
"""The per-step columns: one entry per step, as a list for short episodes and a numpy array otherwise."""
EPISODE_FIELDS = EPISODE_HEADER + EPISODE_COLUMNS
"""Every field of an episode on the wire, in the order they are sent."""
SHORT_EPISODE_STEPS = 16
"""Episodes up to this many steps send their columns as lists, longer ones as numpy arrays."""


@dataclass(frozen=True)
class EpisodeHeader:
    """Which env an episode played and how it was reset: the first fields of `EPISODE_HEADER`, declared once.

    The child's `EpisodeRecord` and the parent's `EpisodeLog` extend it with `reset_options` and the
    columns (each in its own order of defaults; both are checked against `EPISODE_FIELDS` at import).

    Attributes:
        env_index: which env instance, numbered in the order of its first reset within the call.
        requested_id: the id the student asked for (`"Blackjack-v0"`).
        env_id: the gymnasium id actually made (`"Blackjack-v1"`).
        env_kwargs: the other `gymnasium.make` arguments (`max_episode_steps` included when given);
            `gymnasium.make(env_id, **env_kwargs)` rebuilds the env.
        reset_seed: the seed the episode was actually reset with (grader-chosen or mapped).
        student_seed: the seed the student passed to reset, if any.
    """

    env_index: int
    requested_id: str
    env_id: str
    env_kwargs: dict[str, Any]
    reset_seed: int
    student_seed: int | None


def check_declaration(declared: tuple[str, ...], where: str) -> None:
    """Refuse a model of the wire episode whose fields are not `EPISODE_FIELDS` in order.

    Raises:
        TypeError: `declared` differs from `EPISODE_FIELDS` (a programming error, raised at import).
    """
    if declared != EPISODE_FIELDS:
        raise TypeError(
            f"{where} declares the episode fields {declared}, expected {EPISODE_FIELDS} (grader/sandbox/child/episode_fields.py is the one declaration: change it there and in the models)"  # noqa: E501
        )
