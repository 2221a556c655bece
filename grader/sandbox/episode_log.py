"""`EpisodeLog`: one episode as the student's code played it, decoded by a declared model from the child.

The child sends each episode in the layout `grader.sandbox.child.episode_fields` declares (`EPISODE_HEADER`
and `EPISODE_COLUMNS`: per-step columns as numpy arrays, or plain lists for short episodes), a stdlib-only
module the child's recorder imports too. `WireEpisode` is that layout on the parent's side (pydantic,
strict, no other fields); it and `EpisodeLog` are checked against the declaration at import.
`episodes_from_plain` validates it, checks the call's budget from list lengths and array shapes, and only
then decodes arrays. Nothing in a log is trusted: `grader.sandbox.replay` replays it.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import AfterValidator, Field, TypeAdapter, ValidationError, with_config
from typing_extensions import TypedDict

from grader.sandbox.boundary import STRICT, describe, one_of, problem
from grader.sandbox.child.episode_fields import (
    EPISODE_COLUMNS,
    EPISODE_FIELDS,
    EpisodeHeader,
    check_declaration,
)
from grader.sandbox.child.errors import InvalidEpisodeLogError, InvalidValueError
from grader.sandbox.child.frames import MAX_DEPTH, MAX_INT_BITS, NDARRAY_TAG, decode_value, paused_gc
from grader.sandbox.limits import CallBudget
from grader.sandbox.text import clean_plain, clean_text

MAX_ID_LENGTH = 200
MAX_SEED = 2**64
ARRAY_BATCH = 256
"""Array columns decoded by one `decode_value` call."""


@dataclass(frozen=True, eq=False)
class EpisodeLog(EpisodeHeader):
    """One episode: which env, how it was reset (`EpisodeHeader`), and every step the student took.

    Attributes:
        actions: one per step: int for `Discrete`, a numpy array for `Box` (dtype as the student sent it).
        rewards: what the student saw, one per step.
        terminated: the flags the student saw, one per step.
        truncated: likewise. Steps after the first terminated/truncated are kept.
        reset_options: the `options` passed to reset, if any.
    """

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
        fields = tuple(name for name in EPISODE_FIELDS if name != "actions")  # actions: below, by type
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


@dataclass(frozen=True)
class PlainList:
    """A per-step column of plain values that are not all ints (a `Box` env's actions, say): it is decoded
    as plain data (`decode_value`) only after the budget check."""

    items: list[Any]


class ArraySpec(TypedDict):
    """The payload of a tagged numpy array: its data are decoded (and sized against the shape) later."""

    dtype: str
    shape: Annotated[list[Annotated[int, Field(ge=0, lt=2**62)]], Field(max_length=MAX_DEPTH)]
    data: str


class TaggedArray(TypedDict):
    """`{"$ndarray": {...}}`, a column sent as one array (`grader.sandbox.child.frames`)."""

    spec: Annotated[ArraySpec, Field(alias=NDARRAY_TAG)]


TaggedFloat = TypedDict("TaggedFloat", {"$float": Literal["nan", "inf", "-inf"]})
"""A non-finite reward in a list column (JSON has no NaN): `{"$float": "nan"}`."""

Int = Annotated[int, Field(gt=-(2**MAX_INT_BITS), lt=2**MAX_INT_BITS)]
Seed = Annotated[int, Field(ge=0, lt=MAX_SEED)]
EnvId = Annotated[
    str,
    Field(min_length=1, max_length=MAX_ID_LENGTH),
    AfterValidator(lambda text: clean_text(text, MAX_ID_LENGTH)),
]
Number = Annotated[
    Annotated[float, Field(allow_inf_nan=False)]
    | Annotated[TaggedFloat, AfterValidator(lambda tag: float(tag["$float"]))],
    Field(union_mode="left_to_right"),
]
"""A reward in a list column, as a float: an int (converted exactly as `float()` does), a finite float, or
a tagged non-finite one."""
Actions = Annotated[
    list[Int] | TaggedArray | Annotated[list[Any], AfterValidator(PlainList)],
    Field(union_mode="left_to_right"),
    one_of("should be a list of actions or an int array"),
]
Rewards = Annotated[
    list[Number] | TaggedArray,
    Field(union_mode="left_to_right"),
    one_of("should be a list of numbers or a numeric array"),
]
Flags = Annotated[
    list[bool] | TaggedArray,
    Field(union_mode="left_to_right"),
    one_of("should be a list of bools or a bool array"),
]


@with_config(STRICT)
class WireEpisode(TypedDict):
    """One episode as the child sends it (`EpisodeRecord.to_plain`), validated but not yet decoded."""

    env_index: Annotated[int, Field(ge=0, lt=2**31)]
    requested_id: EnvId
    env_id: EnvId
    env_kwargs: dict[str, Any]
    reset_seed: Seed
    student_seed: Seed | None
    reset_options: dict[str, Any] | None
    actions: Actions
    rewards: Rewards
    terminated: Flags
    truncated: Flags


check_declaration(tuple(WireEpisode.__annotations__), "episode_log.WireEpisode")
check_declaration(
    tuple(sorted(EpisodeLog.__dataclass_fields__, key=EPISODE_FIELDS.index)), "episode_log.EpisodeLog"
)

WIRE_EPISODES: TypeAdapter[list[WireEpisode]] = TypeAdapter(
    Annotated[list[WireEpisode], Field(fail_fast=True)]
)
"""Validates the `episodes` of a result frame, stopping at the first bad episode."""


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
    if budget is not None and type(data) is list and len(data) > budget.max_episodes:
        raise InvalidEpisodeLogError(
            f"the log holds {len(data):,} episodes, more than the call's limit of {budget.max_episodes:,}"
        )
    with paused_gc():
        try:
            episodes = WIRE_EPISODES.validate_python(data)
        except ValidationError as error:
            raise InvalidEpisodeLogError(_problem(error)) from None
        if budget is not None:
            _check_steps(episodes, budget)
        arrays = _decoded_arrays(episodes)
        mappings: dict[tuple[Any, ...], dict[str, Any]] = {}
        return [
            _episode(episode, f"episode {number}", arrays, mappings)
            for number, episode in enumerate(episodes)
        ]


def _problem(error: ValidationError) -> str:
    location = error.errors(include_url=False)[0]["loc"]
    if location and type(location[0]) is int:
        return problem(error, f"episode {location[0]}", skip=1)
    return problem(error, "the episode log")


def _check_steps(episodes: list[WireEpisode], budget: CallBudget) -> None:
    steps = 0
    for episode in episodes:
        steps += max(_length(episode[name]) for name in EPISODE_COLUMNS)  # type: ignore[literal-required]
        if steps > budget.max_steps:
            raise InvalidEpisodeLogError(
                f"the log holds more than {budget.max_steps:,} steps, the call's limit"
            )


def _length(column: list[Any] | PlainList | TaggedArray) -> int:
    """Entries of a per-step column as announced (list length or array shape), without decoding it."""
    if isinstance(column, list):
        return len(column)
    if isinstance(column, PlainList):
        return len(column.items)
    shape = column["spec"]["shape"]
    return shape[0] if shape else 0


def _decoded_arrays(episodes: list[WireEpisode]) -> Iterator[np.ndarray]:
    """Every array column of the log, episode by episode in `EPISODE_COLUMNS` order (the order `_episode`
    takes them in), decoded `ARRAY_BATCH` at a time: one decoder per batch, not one per column, and only a
    batch of arrays alive at once."""
    columns = [
        (number, name, column["spec"])
        for number, episode in enumerate(episodes)
        for name in EPISODE_COLUMNS
        if isinstance(column := episode[name], dict)  # type: ignore[literal-required]
    ]
    for start in range(0, len(columns), ARRAY_BATCH):
        batch = columns[start : start + ARRAY_BATCH]
        try:
            arrays: list[np.ndarray] = decode_value([{NDARRAY_TAG: spec} for _, _, spec in batch], "the log")
        except InvalidValueError:
            for number, name, spec in batch:  # the first bad one again, for a message that names it
                _decoded({NDARRAY_TAG: spec}, f"episode {number}: {name}")
            raise
        yield from arrays


def _episode(
    episode: WireEpisode,
    where: str,
    arrays: Iterator[np.ndarray],
    mappings: dict[tuple[Any, ...], dict[str, Any]],
) -> EpisodeLog:
    actions = _actions(episode["actions"], arrays, f"{where}: actions")
    rewards = _rewards(episode["rewards"], arrays, f"{where}: rewards")
    terminated = _flags(episode["terminated"], arrays, f"{where}: terminated")
    truncated = _flags(episode["truncated"], arrays, f"{where}: truncated")
    if not len(actions) == len(rewards) == len(terminated) == len(truncated):
        raise InvalidEpisodeLogError(
            f"{where}: actions, rewards, terminated and truncated must have one entry per step, found {len(actions)}, {len(rewards)}, {len(terminated)} and {len(truncated)}"  # noqa: E501
        )
    reset_options = episode["reset_options"]
    return EpisodeLog(
        env_index=episode["env_index"],
        requested_id=episode["requested_id"],
        env_id=episode["env_id"],
        env_kwargs=_env_kwargs(episode["env_kwargs"], f"{where}: env_kwargs", mappings),
        reset_seed=episode["reset_seed"],
        student_seed=episode["student_seed"],
        actions=actions,
        rewards=rewards,
        terminated=terminated,
        truncated=truncated,
        reset_options=None if reset_options is None else _mapping(reset_options, f"{where}: reset_options"),
    )


def _actions(
    column: list[int] | PlainList | TaggedArray, arrays: Iterator[np.ndarray], where: str
) -> list[Any]:
    if isinstance(column, list):
        return column
    if isinstance(column, PlainList):
        return _decoded(column.items, where)  # type: ignore[no-any-return]
    return _array(next(arrays), "iu", where).tolist()  # type: ignore[no-any-return]


def _rewards(column: list[Any] | TaggedArray, arrays: Iterator[np.ndarray], where: str) -> list[float]:
    if isinstance(column, list):
        return column
    return _array(next(arrays), "biuf", where).astype(np.float64).tolist()  # type: ignore[no-any-return]


def _flags(column: list[bool] | TaggedArray, arrays: Iterator[np.ndarray], where: str) -> list[bool]:
    if isinstance(column, list):
        return column
    return _array(next(arrays), "b", where).tolist()  # type: ignore[no-any-return]


def _array(array: np.ndarray, kinds: str, where: str) -> np.ndarray:
    if array.ndim != 1 or array.dtype.kind not in kinds:
        raise InvalidEpisodeLogError(
            f"{where} should be a 1-D array of kind {kinds!r} or a list, found {describe(array)}"
        )
    return array


def _env_kwargs(
    value: dict[str, Any], where: str, decoded: dict[tuple[Any, ...], dict[str, Any]]
) -> dict[str, Any]:
    """`_mapping` of an episode's env arguments, decoded once per call for arguments of plain scalars.

    Every episode of one env repeats the same arguments (Blackjack's `natural` and `sab`, 10 000 games a
    call); the key holds each value's type, so `True` and `1` stay apart. Each episode gets its own copy.
    """
    if not value:
        return value
    try:
        key = tuple((name, type(item), item) for name, item in value.items())
        known = decoded.get(key)
    except TypeError:  # a list or dict among the values: decoded every time
        return _mapping(value, where)
    if known is None:
        known = decoded[key] = _mapping(value, where)
    return dict(known)


def _mapping(value: dict[str, Any], where: str) -> dict[str, Any]:
    if not value:  # the common case, without a decoder's set-up
        return value
    decoded = clean_plain(_decoded(value, where))
    if type(decoded) is not dict:
        raise InvalidEpisodeLogError(f"{where} should be a dict, found {describe(decoded)}")
    return decoded


def _decoded(value: Any, where: str) -> Any:
    """`decode_value` for one field of the log, its errors as `InvalidEpisodeLogError`."""
    try:
        return decode_value(value, f"the episode log ({where})")
    except InvalidValueError as error:
        raise InvalidEpisodeLogError(error.message) from None
