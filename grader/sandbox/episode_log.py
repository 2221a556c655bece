"""`EpisodeLog`: one episode as the student's code played it, decoded strictly from the result channel.

The child sends each episode in the layout of `grader.sandbox.child.recorder.EpisodeRecord.to_plain`
(per-step columns as numpy arrays, or plain lists for short episodes). Nothing in a log is trusted:
`grader.sandbox.replay` replays it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from grader.sandbox.child.errors import InvalidEpisodeLogError, InvalidValueError
from grader.sandbox.child.frames import MAX_INT_BITS, NDARRAY_TAG, decode_value, paused_gc
from grader.sandbox.outcome import CallBudget
from grader.sandbox.text import clean_plain, clean_text

MAX_ID_LENGTH = 200
MAX_SEED = 2**64
_LARGEST_INT = 2**MAX_INT_BITS
_NUMBER_TYPES = frozenset({int, float})
_INT_TYPE = frozenset({int})
_BOOL_TYPE = frozenset({bool})
_COLUMNS = ("actions", "rewards", "terminated", "truncated")
_FIELDS = frozenset(
    {
        "env_index",
        "requested_id",
        "env_id",
        "env_kwargs",
        "reset_seed",
        "student_seed",
        "reset_options",
        "actions",
        "rewards",
        "terminated",
        "truncated",
    }
)


@dataclass(frozen=True, eq=False)
class EpisodeLog:
    """One episode: which env, how it was reset, and every step the student took.

    Attributes:
        env_index: which env instance, numbered in the order of its first reset within the call.
        requested_id: the id the student asked for (`"Blackjack-v0"`).
        env_id: the gymnasium id actually made (`"Blackjack-v1"`).
        env_kwargs: the other `gymnasium.make` arguments (`max_episode_steps` included when given);
            `gymnasium.make(env_id, **env_kwargs)` rebuilds the env.
        reset_seed: the seed the episode was actually reset with (grader-chosen or mapped).
        student_seed: the seed the student passed to reset, if any.
        actions: one per step: int for `Discrete`, a numpy array for `Box` (dtype as the student sent it).
        rewards: what the student saw, one per step.
        terminated: the flags the student saw, one per step.
        truncated: likewise. Steps after the first terminated/truncated are kept.
        reset_options: the `options` passed to reset, if any.
    """

    env_index: int
    requested_id: str
    env_id: str
    env_kwargs: dict[str, Any]
    reset_seed: int
    student_seed: int | None
    actions: list[Any]
    rewards: list[float]
    terminated: list[bool]
    truncated: list[bool]
    reset_options: dict[str, Any] | None = None

    @property
    def steps(self) -> int:
        """Number of steps logged, including steps after the episode ended."""
        return len(self.actions)

    def __eq__(self, other: object) -> bool:
        """Field by field; array actions (Box envs) compare by dtype, shape and values."""
        if not isinstance(other, EpisodeLog):
            return NotImplemented
        fields = (
            "env_index",
            "requested_id",
            "env_id",
            "env_kwargs",
            "reset_seed",
            "student_seed",
            "rewards",
            "terminated",
            "truncated",
            "reset_options",
        )
        return (
            all(getattr(self, name) == getattr(other, name) for name in fields)
            and len(self.actions) == len(other.actions)
            and all(
                _same_action(mine, theirs) for mine, theirs in zip(self.actions, other.actions, strict=True)
            )
        )

    __hash__ = None  # type: ignore[assignment]  # mutable lists inside


def _same_action(mine: Any, theirs: Any) -> bool:
    if type(mine) is np.ndarray or type(theirs) is np.ndarray:
        return type(mine) is type(theirs) and mine.dtype == theirs.dtype and np.array_equal(mine, theirs)
    return bool(type(mine) is type(theirs) and mine == theirs)


def episodes_from_plain(data: Any, budget: CallBudget | None = None) -> list[EpisodeLog]:
    """Decode and validate the `episodes` field of a result frame (JSON data, as parsed).

    Each per-step column is either a tagged numpy array or, for short episodes, a plain list.

    Args:
        data: The parsed field.
        budget: The call's budget: more episodes, or more steps summed over them, are refused from the
            list lengths and array shapes, before any array is decoded.

    Raises:
        InvalidEpisodeLogError: the data does not have the layout the child sends, or exceeds `budget`.
    """
    if type(data) is not list:
        raise InvalidEpisodeLogError(f"episodes must be a list, found {type(data).__name__}")
    if budget is not None:
        _check_budget(data, budget)
    with paused_gc():
        return [_episode(item, number) for number, item in enumerate(data)]


def _check_budget(data: list[Any], budget: CallBudget) -> None:
    if len(data) > budget.max_episodes:
        raise InvalidEpisodeLogError(
            f"the log holds {len(data):,} episodes, more than the call's limit of {budget.max_episodes:,}"
        )
    steps = 0
    for item in data:
        if type(item) is dict:
            steps += max((_column_length(item.get(name)) for name in _COLUMNS), default=0)
        if steps > budget.max_steps:
            raise InvalidEpisodeLogError(
                f"the log holds more than {budget.max_steps:,} steps, the call's limit"
            )


def _column_length(column: Any) -> int:
    """Entries of a per-step column as announced (list length or array shape), without decoding it."""
    if type(column) is list:
        return len(column)
    spec = column.get(NDARRAY_TAG) if type(column) is dict else None
    shape = spec.get("shape") if type(spec) is dict else None
    if type(shape) is list and shape and all(type(size) is int and size >= 0 for size in shape):
        return int(shape[0])
    return 0  # not a column the decoder accepts: refused there


def _episode(item: Any, number: int) -> EpisodeLog:
    where = f"episode {number}"
    if type(item) is not dict or item.keys() != _FIELDS:
        item = _decoded(item, where)
        found = sorted(item) if type(item) is dict else type(item).__name__
        raise InvalidEpisodeLogError(f"{where} must have the fields {sorted(_FIELDS)}, found {found}")
    student_seed = item["student_seed"]
    if student_seed is not None:
        student_seed = _seed(student_seed, f"{where}: student_seed")
    rewards = _rewards(item["rewards"], f"{where}: rewards")
    terminated = _flags(item["terminated"], f"{where}: terminated")
    truncated = _flags(item["truncated"], f"{where}: truncated")
    actions = _actions(item["actions"], f"{where}: actions")
    if not len(actions) == len(rewards) == len(terminated) == len(truncated):
        raise InvalidEpisodeLogError(
            f"{where}: actions, rewards, terminated and truncated must have one entry per step, found {len(actions)}, {len(rewards)}, {len(terminated)} and {len(truncated)}"  # noqa: E501
        )
    reset_options = item["reset_options"]
    return EpisodeLog(
        env_index=_bounded_int(item["env_index"], 0, 2**31, f"{where}: env_index"),
        requested_id=_identifier(item["requested_id"], f"{where}: requested_id"),
        env_id=_identifier(item["env_id"], f"{where}: env_id"),
        env_kwargs=_mapping(item["env_kwargs"], f"{where}: env_kwargs"),
        reset_seed=_seed(item["reset_seed"], f"{where}: reset_seed"),
        student_seed=student_seed,
        actions=actions,
        rewards=rewards,
        terminated=terminated,
        truncated=truncated,
        reset_options=None if reset_options is None else _mapping(reset_options, f"{where}: reset_options"),
    )


def _decoded(value: Any, where: str) -> Any:
    """`decode_value` for one field of the log, its errors as `InvalidEpisodeLogError`."""
    try:
        return decode_value(value, f"the episode log ({where})")
    except InvalidValueError as error:
        raise InvalidEpisodeLogError(error.message) from None


def _array(value: Any, kinds: str, where: str) -> np.ndarray:
    array = _decoded(value, where) if type(value) is dict else value
    if type(array) is not np.ndarray or array.ndim != 1 or array.dtype.kind not in kinds:
        raise InvalidEpisodeLogError(
            f"{where} must be a 1-D array of kind {kinds!r} or a list, found {_describe(array)}"
        )
    return array


def _rewards(value: Any, where: str) -> list[float]:
    if type(value) is not list:
        return _array(value, "biuf", where).astype(np.float64).tolist()  # type: ignore[no-any-return]
    numbers = value if _plain_numbers(value) else _decoded(value, where)
    if not _plain_numbers(numbers):
        raise InvalidEpisodeLogError(f"{where} must hold only numbers, found {_describe(value)}")
    rewards = [float(number) for number in numbers]
    if not all(map(math.isfinite, rewards)) and numbers is value:
        _decoded(value, where)  # an untagged non-finite float: the protocol's own error
    return rewards


def _plain_numbers(values: list[Any]) -> bool:
    """Only floats and ints small enough for a float (what `decode_value` accepts untagged)."""
    return set(map(type, values)) <= _NUMBER_TYPES and all(
        type(value) is float or -_LARGEST_INT < value < _LARGEST_INT for value in values
    )


def _flags(value: Any, where: str) -> list[bool]:
    if type(value) is not list:
        return _array(value, "b", where).tolist()  # type: ignore[no-any-return]
    if not set(map(type, value)) <= _BOOL_TYPE:
        raise InvalidEpisodeLogError(f"{where} must hold only bools, found {_describe(value)}")
    return list(value)


def _actions(value: Any, where: str) -> list[Any]:
    if type(value) is list:
        if set(map(type, value)) <= _INT_TYPE and all(
            -_LARGEST_INT < action < _LARGEST_INT for action in value
        ):
            return list(value)
        return _decoded(value, where)  # type: ignore[no-any-return]
    if type(value) is dict:
        return _array(value, "iu", where).tolist()  # type: ignore[no-any-return]
    raise InvalidEpisodeLogError(f"{where} must be an int array or a list, found {_describe(value)}")


def _seed(value: Any, where: str) -> int:
    return _bounded_int(value, 0, MAX_SEED, where)


def _bounded_int(value: Any, low: int, high: int, where: str) -> int:
    if type(value) is not int or not low <= value < high:
        raise InvalidEpisodeLogError(f"{where} must be an int in [{low}, {high}), found {_describe(value)}")
    return value


def _identifier(value: Any, where: str) -> str:
    if type(value) is not str or not 0 < len(value) <= MAX_ID_LENGTH:
        raise InvalidEpisodeLogError(f"{where} must be a non-empty str of at most {MAX_ID_LENGTH} characters")
    return clean_text(value, MAX_ID_LENGTH)


def _mapping(value: Any, where: str) -> dict[str, Any]:
    if type(value) is not dict:
        raise InvalidEpisodeLogError(f"{where} must be a dict, found {_describe(value)}")
    return clean_plain(_decoded(value, where))  # type: ignore[no-any-return]


def _describe(value: Any) -> str:
    if type(value) is np.ndarray:
        return f"an array of dtype {value.dtype} and shape {value.shape}"
    text = repr(value)
    return f"{type(value).__name__} {text[:60]}"
