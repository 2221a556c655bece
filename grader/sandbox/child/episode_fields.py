"""The fields of an episode and of a call's columnar episode log on the wire, declared once for both sides.

Standard library only (the child imports it before the student's code, the parent without the child's
gymnasium set-up). An episode has the fields `EPISODE_FIELDS` (the child's `EpisodeRecord`, the parent's
`EpisodeLog`, the in-process simulation of `grader.simulated_students`). A call's episodes travel as one
block with the keys `LOG_FIELDS` (`grader.sandbox.child.log_block` builds it,
`grader.sandbox.episode_log.WireLog` validates it): the made-env fields as a table of distinct descriptions,
the other header fields as per-episode columns (sparse where mostly absent), the per-step columns concatenated
over all episodes, and one array of episode lengths. Both models are checked against these declarations at
import.
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
"""The per-step columns: one entry per step."""
EPISODE_FIELDS = EPISODE_HEADER + EPISODE_COLUMNS
"""Every field of an episode, in this order."""

MADE_FIELDS = ("requested_id", "env_id", "env_kwargs")
"""How an episode's env was made: the fields of one entry of the log's `envs` table (distinct entries)."""
DENSE_FIELDS = ("env_index", "reset_seed")
"""Header fields every episode has: one integer array each, one entry per episode."""
SPARSE_FIELDS = ("student_seed", "reset_options")
"""Header fields most episodes leave empty (None): `{"episodes": int array, "values": ...}` where present."""
LOG_FIELDS = ("envs", "made", *DENSE_FIELDS, *SPARSE_FIELDS, "lengths", "action_form", *EPISODE_COLUMNS)
"""The keys of a call's episode log on the wire, in the order they are sent:

- `envs`: the distinct `MADE_FIELDS` dicts of the call; `made`: per episode, its index in `envs`;
- `env_index`, `reset_seed`: per episode; `student_seed`, `reset_options`: sparse, as above;
- `lengths`: per episode, its steps; the per-step columns hold `sum(lengths)` entries, episode after episode;
- `action_form`: one of `ACTION_FORMS`, how `actions` is sent.
"""
ACTION_FORMS = ("int", "array", "plain")
"""`actions` as a 1-D int array (`Discrete` envs: every action a plain int); as one array of shape
(steps, *shape) when every action is a numpy array of one shape and dtype (`Box` envs, one step per row);
else as one plain list of the actions (any mix the student passed, each decoded as plain data)."""


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


def check_log_declaration(declared: tuple[str, ...], where: str) -> None:
    """Refuse a model of the wire log whose keys are not `LOG_FIELDS` in order (see `check_declaration`).

    Raises:
        TypeError: `declared` differs from `LOG_FIELDS`, or `LOG_FIELDS` does not cover `EPISODE_FIELDS`.
    """
    covered = MADE_FIELDS + DENSE_FIELDS + SPARSE_FIELDS + EPISODE_COLUMNS
    if declared != LOG_FIELDS or sorted(covered) != sorted(EPISODE_FIELDS):
        raise TypeError(
            f"{where} declares the log fields {declared}, expected {LOG_FIELDS} covering {EPISODE_FIELDS} (grader/sandbox/child/episode_fields.py is the one declaration: change it there and in the models)"  # noqa: E501
        )


def check_declaration(declared: tuple[str, ...], where: str) -> None:
    """Refuse a model of the wire episode whose fields are not `EPISODE_FIELDS` in order.

    Raises:
        TypeError: `declared` differs from `EPISODE_FIELDS` (a programming error, raised at import).
    """
    if declared != EPISODE_FIELDS:
        raise TypeError(
            f"{where} declares the episode fields {declared}, expected {EPISODE_FIELDS} (grader/sandbox/child/episode_fields.py is the one declaration: change it there and in the models)"  # noqa: E501
        )
