"""A call's episode log as one columnar block, the layout `grader.sandbox.child.episode_fields` declares.

The child's recorder keeps each episode's steps in compact typed arrays (`EpisodeRecord`); `log_block`
concatenates them into one array per column for the whole call, so a 20 000-episode Taxi call or a
10 000-game Blackjack call sends about a dozen arrays instead of four per episode, and the parent
validates one block (`grader.sandbox.episode_log.episodes_from_plain`) instead of one model per episode.
The block is plain data for `grader.sandbox.child.frames.encode_value` (numpy arrays travel as base64).

The wire format:

- The wire format: a call's episodes travel as ONE columnar block (`grader/sandbox/child/log_block.py`
  builds it from the recorder's typed columns; its keys are `LOG_FIELDS` of
  `grader/sandbox/child/episode_fields.py`):
  `envs`, the call's distinct made envs (`requested_id`, `env_id`, `env_kwargs`) and `made`, each
  episode's index in it; `env_index` and `reset_seed` (uint64), one entry per episode; `student_seed` and
  `reset_options` sparse, `{"episodes": [numbers], "values": [...]}` for the episodes that have one;
  `lengths`, each episode's steps; the per-step columns `actions`, `rewards`, `terminated`, `truncated`
  concatenated over the episodes (`sum(lengths)` entries each, smallest int dtype for integral rewards);
  `action_form` says how actions travel: `int` (1-D int array: every action a plain int), `array` (one
  array of shape (steps, *shape): every action a numpy array of one shape and dtype, a `Box` env's), or
  `plain` (one list of plain values, decoded by `decode_value`). Arrays are `$ndarray` base64 tags; a call
  with no episode sends `[]`. The parent's `WireLog` (strict pydantic TypedDict, checked against
  `LOG_FIELDS` at import by `check_log_declaration`) validates the block; `episodes_from_plain` then
  checks every array's dtype and announced shape, the episode and step counts against the call's
  budget and the table's size BEFORE decoding any array; then decodes the per-episode arrays (lengths
  >= 0 summing, in Python ints, to the step columns' length; `made` within the table; `env_index` in
  [0, 2^31); seeds >= 0; sparse episode numbers strictly increasing and in range), then the step
  arrays, one at a time, each split into its episodes' list slices as soon as it is decoded (flags
  normalised to bool from their bytes), and builds the `EpisodeLog`s from them.
  Every failure is an `InvalidEpisodeLogError` saying what was expected and what was found, which the
  runner reports as a forged frame (`INVALID_VALUE`).

The episode's wire fields are declared once in `grader/sandbox/child/episode_fields.py` (stdlib only):
`EPISODE_HEADER`, `EPISODE_COLUMNS`, `EPISODE_FIELDS`, and the frozen dataclass `EpisodeHeader` (env and reset
fields) that the child's `EpisodeRecord` and the parent's `EpisodeLog` extend; and the columnar log's layout,
`MADE_FIELDS`, `DENSE_FIELDS`, `SPARSE_FIELDS`, `LOG_FIELDS`, `ACTION_FORMS`.
`grader/simulated_students/simulation.py` (whose episodes hold an `EpisodeLog`) uses them too;
`check_declaration` and `check_log_declaration` refuse a drifted model or block at import. `RecordingEnv.step`
counts and logs each step in its one frame into typed columns (`array('q')` actions, a list only after an
action that is not an int64; `array('d')` rewards, a NaN for a reward that cannot be converted, which the
replay then reports; `bytearray` flags). Costs: `bench/recorder_cost.py`; a class's:
`bench/class_throughput.py`.
"""

from __future__ import annotations

from array import array
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from grader.sandbox.child.episode_fields import check_log_declaration
from grader.sandbox.child.frames import ARRAY_DTYPES

if TYPE_CHECKING:
    from grader.sandbox.child.recorder import EpisodeRecord

_SCALARS = (str, int, float, bool, type(None))
_INT_RANGES = [
    (dtype, int(np.iinfo(dtype).min), int(np.iinfo(dtype).max)) for dtype in (np.int8, np.int16, np.int32)
]
NO_EPISODES: list[Any] = []
"""What a call that logged no episode sends instead of a block (a call that does not record, say)."""


def log_block(episodes: Sequence[EpisodeRecord]) -> dict[str, Any]:
    """The wire layout of a call's episodes (`episode_fields.LOG_FIELDS`), in reset order.

    Args:
        episodes: The call's episodes as `Recorder.finish_call` returns them.

    Returns:
        A dict of plain data and numpy arrays; its env arguments, reset options and plain-list actions
        are still the student's values, checked by `encode_value` like any returned value.
    """
    envs: list[dict[str, Any]] = []
    table: dict[Any, int] = {}
    made: list[int] = []
    for episode in episodes:
        key = _made_key(episode.requested_id, episode.env_id, episode.env_kwargs)
        number = table.get(key) if key is not None else None
        if number is None:
            number = len(envs)
            envs.append(
                {
                    "requested_id": episode.requested_id,
                    "env_id": episode.env_id,
                    "env_kwargs": episode.env_kwargs,
                }
            )
            if key is not None:
                table[key] = number
        made.append(number)
    seeded = [number for number, episode in enumerate(episodes) if episode.student_seed is not None]
    optioned = [number for number, episode in enumerate(episodes) if episode.reset_options is not None]
    action_form, actions = _actions(episodes)
    return {
        "envs": envs,
        "made": _smallest_ints(made),
        "env_index": _smallest_ints([episode.env_index for episode in episodes]),
        "reset_seed": np.array([episode.reset_seed for episode in episodes], dtype=np.uint64),
        "student_seed": {
            "episodes": _smallest_ints(seeded),
            "values": np.array([episodes[number].student_seed for number in seeded], dtype=np.uint64),
        },
        "reset_options": {
            "episodes": _smallest_ints(optioned),
            "values": [episodes[number].reset_options for number in optioned],
        },
        "lengths": _smallest_ints([len(episode.rewards) for episode in episodes]),
        "action_form": action_form,
        "actions": actions,
        "rewards": _compact_numbers(np.frombuffer(b"".join(episode.rewards for episode in episodes))),
        "terminated": np.frombuffer(b"".join(episode.terminated for episode in episodes), dtype=np.bool_),
        "truncated": np.frombuffer(b"".join(episode.truncated for episode in episodes), dtype=np.bool_),
    }


def _made_key(requested_id: Any, env_id: Any, env_kwargs: Any) -> Any:
    """A key telling equal made envs apart exactly (types included: `True` is not `1`), or None when the
    arguments hold anything but plain scalars (such an env gets its own table entry)."""
    if type(env_kwargs) is not dict or type(requested_id) is not str or type(env_id) is not str:
        return None
    if not all(type(value) in _SCALARS for value in env_kwargs.values()):
        return None
    return (requested_id, env_id, tuple((name, type(value), value) for name, value in env_kwargs.items()))


def _actions(episodes: Sequence[EpisodeRecord]) -> tuple[str, Any]:
    """`(action_form, actions)`: one int array when every episode kept its actions as 64-bit ints, one
    array of rows when every action is a numpy array of one shape and dtype, else one plain list."""
    if all(type(episode.actions) is array for episode in episodes):
        joined = b"".join(episode.actions for episode in episodes)  # type: ignore[misc]
        return "int", _smallest_int_array(np.frombuffer(joined, dtype=np.int64))
    actions = [action for episode in episodes for action in episode.actions]
    kinds = set(map(type, actions))
    if kinds == {int}:
        try:
            return "int", _smallest_int_array(np.array(actions, dtype=np.int64))
        except OverflowError:
            return "plain", actions
    if kinds == {np.ndarray}:
        shapes = {(action.shape, action.dtype.str) for action in actions}  # type: ignore[union-attr]
        if len(shapes) == 1 and next(iter(shapes))[1] in ARRAY_DTYPES:
            return "array", np.stack(actions)
    return "plain", actions


def _smallest_ints(values: list[int]) -> np.ndarray:
    """`values` (each within int64) in the smallest int dtype that holds them."""
    return _smallest_int_array(np.array(values, dtype=np.int64))


def _compact_numbers(values: np.ndarray) -> np.ndarray:
    """The smallest dtype that holds `values` exactly (Taxi's and Blackjack's rewards fit int8)."""
    if values.size and np.all(np.abs(values) < 2**31) and np.all(values == np.trunc(values)):
        return _smallest_int_array(values.astype(np.int64))
    return values


def _smallest_int_array(values: np.ndarray) -> np.ndarray:
    if values.size == 0:
        return values.astype(np.int8)
    return values.astype(_smallest_dtype(int(values.min()), int(values.max())))


def _smallest_dtype(low: int, high: int) -> type[np.signedinteger[Any]]:
    for dtype, smallest, largest in _INT_RANGES:
        if smallest <= low and high <= largest:
            return dtype
    return np.int64


check_log_declaration(tuple(log_block(())), "log_block.log_block")
