"""`EpisodeLog`: one episode as the student's code played it, decoded by a declared model from the child.

The child sends a call's episodes as one columnar block in the layout `grader.sandbox.child.episode_fields`
declares (`LOG_FIELDS`: a table of made envs, per-episode arrays, per-step arrays concatenated over the
episodes, one array of lengths), a stdlib-only module the child's recorder imports too. `WireLog` is that
layout on the parent's side (pydantic, strict, no other fields); it and `EpisodeLog` are checked against the
declaration at import. `episodes_from_plain` validates the block, checks the call's budget and every
array's dtype and shape from what they announce, and only then decodes arrays; each `EpisodeLog` holds
slices of the decoded columns. Nothing in a log is trusted: `grader.sandbox.replay` replays it.
"""

from __future__ import annotations

import itertools
import json
from dataclasses import dataclass
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import AfterValidator, Field, TypeAdapter, ValidationError, with_config
from typing_extensions import TypedDict

from grader.sandbox.boundary import STRICT, describe, one_of, problem
from grader.sandbox.child.episode_fields import (
    ACTION_FORMS,
    EPISODE_FIELDS,
    EpisodeHeader,
    check_declaration,
    check_log_declaration,
)
from grader.sandbox.child.errors import InvalidEpisodeLogError, InvalidValueError
from grader.sandbox.child.frames import (
    ARRAY_DTYPES,
    MAX_DEPTH,
    NDARRAY_TAG,
    decode_array,
    decode_value,
    paused_gc,
)
from grader.sandbox.limits import CallBudget
from grader.sandbox.text import clean_plain, clean_text

MAX_ID_LENGTH = 200
MAX_SEED = 2**64
MAX_REMEMBERED_KEYS = 1024
"""Distinct environments whose `environment_key` is remembered per process (a call makes a few); when
full, it starts afresh, so a worker that graded many files keeps remembering."""
MAX_REMEMBERED_KEY_LENGTH = 1024
"""Longer keys (a string argument a student made long) are made again each time, never kept."""
_SCALAR_KINDS = frozenset({str, int, bool, type(None)})
"""Argument types remembered by value and type: equal values of these types have the same JSON text
(floats are not: ``0.0 == -0.0``; containers are not: ``[1] == [True]``)."""
_REMEMBERED_KEYS: dict[tuple[Any, ...], str] = {}


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
    def environment(self) -> str:
        """`environment_key` of the env the episode was played in (its id and arguments), made once."""
        # In the instance's own dict: `functools.cached_property` takes a lock that costs more than the key.
        key = self.__dict__.get("_environment")
        if key is None:
            key = self.__dict__["_environment"] = environment_key(self.env_id, self.env_kwargs)
        return key

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


def environment_key(env_id: str, env_kwargs: dict[str, Any]) -> str:
    """One text per environment (id and arguments, in any order): a cache's or a grouping's key.

    The JSON of ``[env_id, env_kwargs]`` with sorted keys (`repr` for what JSON cannot hold). Tens of
    thousands of logged episodes share a few environments, so the text of arguments that are all plain
    scalars is remembered by (name, type, value) and made once per process.
    """
    items = []
    for name, value in env_kwargs.items():
        if type(value) not in _SCALAR_KINDS or type(name) is not str:
            return _key_text(env_id, env_kwargs)
        items.append((name, type(value).__name__, value))
    signature = (env_id, *sorted(items))
    key = _REMEMBERED_KEYS.get(signature)
    if key is None:
        key = _key_text(env_id, env_kwargs)
        if len(key) <= MAX_REMEMBERED_KEY_LENGTH:
            if len(_REMEMBERED_KEYS) >= MAX_REMEMBERED_KEYS:
                _REMEMBERED_KEYS.clear()
            _REMEMBERED_KEYS[signature] = key
    return key


def _key_text(env_id: str, env_kwargs: dict[str, Any]) -> str:
    return json.dumps([env_id, env_kwargs], sort_keys=True, default=repr)


def _same_action(mine: Any, theirs: Any) -> bool:
    if type(mine) is np.ndarray or type(theirs) is np.ndarray:
        return type(mine) is type(theirs) and mine.dtype == theirs.dtype and np.array_equal(mine, theirs)
    return bool(type(mine) is type(theirs) and mine == theirs)


class ArraySpec(TypedDict):
    """The payload of a tagged numpy array: its data are decoded (and sized against the shape) later."""

    dtype: str
    shape: Annotated[list[Annotated[int, Field(ge=0, lt=2**62)]], Field(max_length=MAX_DEPTH)]
    data: str


@with_config(STRICT)
class TaggedArray(TypedDict):
    """`{"$ndarray": {...}}`, a column sent as one array (`grader.sandbox.child.frames`)."""

    spec: Annotated[ArraySpec, Field(alias=NDARRAY_TAG)]


EnvId = Annotated[
    str,
    Field(min_length=1, max_length=MAX_ID_LENGTH),
    AfterValidator(lambda text: clean_text(text, MAX_ID_LENGTH)),
]


@with_config(STRICT)
class WireMade(TypedDict):
    """One entry of the log's `envs` table: how an env was made (`episode_fields.MADE_FIELDS`)."""

    requested_id: EnvId
    env_id: EnvId
    env_kwargs: dict[str, Any]


@with_config(STRICT)
class SparseSeeds(TypedDict):
    """`student_seed` where the student passed one: the episodes' numbers and their seeds."""

    episodes: TaggedArray
    values: TaggedArray


@with_config(STRICT)
class SparseOptions(TypedDict):
    """`reset_options` where the student passed some: the episodes' numbers and their options."""

    episodes: TaggedArray
    values: list[dict[str, Any]]


@with_config(STRICT)
class WireLog(TypedDict):
    """A call's episode log as the child sends it (`grader.sandbox.child.log_block`), before decoding."""

    envs: list[WireMade]
    made: TaggedArray
    env_index: TaggedArray
    reset_seed: TaggedArray
    student_seed: SparseSeeds
    reset_options: SparseOptions
    lengths: TaggedArray
    action_form: Literal[ACTION_FORMS]  # type: ignore[valid-type]
    actions: Annotated[
        TaggedArray | list[Any],
        Field(union_mode="left_to_right"),
        one_of("should be an array or a list of actions"),
    ]
    rewards: TaggedArray
    terminated: TaggedArray
    truncated: TaggedArray


check_log_declaration(tuple(WireLog.__annotations__), "episode_log.WireLog")
check_declaration(
    tuple(sorted(EpisodeLog.__dataclass_fields__, key=EPISODE_FIELDS.index)), "episode_log.EpisodeLog"
)

WIRE_LOG: TypeAdapter[WireLog] = TypeAdapter(WireLog)
"""Validates the `episodes` of a result frame: its structure, array specs and table, no array data."""


def episodes_from_plain(data: Any, budget: CallBudget | None = None) -> list[EpisodeLog]:
    """Validate and decode the `episodes` field of a result frame (JSON data, as parsed): one columnar block.

    Everything announced is checked before any array is decoded: the block's structure, every array's
    dtype and shape, the episode count and the step count against `budget`, the table's size. Then the
    per-episode arrays (lengths summing to the step count, table indices in range, seeds non-negative),
    then the per-step arrays; each episode's columns are slices of them.

    Args:
        data: The parsed field: a block, or `[]` for a call that logged no episode.
        budget: The call's budget: more episodes, or more steps, are refused from the announced shapes.

    Raises:
        InvalidEpisodeLogError: the data does not have the layout the child sends, or exceeds `budget`;
            the message says what was expected and what was found.
    """
    if type(data) is list and not data:  # `log_block.NO_EPISODES`
        return []
    if budget is not None:
        _check_tables(data, budget)
    with paused_gc():
        try:
            log = WIRE_LOG.validate_python(data)
        except ValidationError as error:
            raise InvalidEpisodeLogError(problem(error, "the episode log")) from None
        episodes, steps = _announced(log, budget)
        lengths = _ints(log["lengths"], "lengths", 0, steps)
        if sum(lengths) != steps:
            raise InvalidEpisodeLogError(
                f"the episode log: lengths should sum to the {steps:,} entries of each per-step column, found a sum of {sum(lengths):,}"  # noqa: E501
            )
        made = _ints(log["made"], "made", 0, len(log["envs"]) - 1)
        env_indices = _ints(log["env_index"], "env_index", 0, 2**31 - 1)
        reset_seeds = _ints(log["reset_seed"], "reset_seed", 0, MAX_SEED - 1)
        student_seeds = dict(
            zip(
                _positions(log["student_seed"]["episodes"], "student_seed", episodes),
                _ints(log["student_seed"]["values"], "student_seed.values", 0, MAX_SEED - 1),
                strict=True,
            )
        )
        options = _sparse_options(log["reset_options"], episodes)
        envs = [
            (entry["requested_id"], entry["env_id"], _mapping(entry["env_kwargs"], f"envs[{number}]"))
            for number, entry in enumerate(log["envs"])
        ]
        ends = list(itertools.accumulate(lengths))
        bounds = list(zip([0, *ends], ends, strict=False))
        # Each column is split as soon as it is decoded: one whole column alive at a time, not four.
        actions = _split(_actions(log["action_form"], log["actions"], steps), bounds)
        rewards = _split(_array(log["rewards"], "rewards").astype(np.float64).tolist(), bounds)
        terminated = _split((_array(log["terminated"], "terminated").view(np.uint8) != 0).tolist(), bounds)
        truncated = _split((_array(log["truncated"], "truncated").view(np.uint8) != 0).tolist(), bounds)
        logs = []
        for number, made_number in enumerate(made):
            requested_id, env_id, env_kwargs = envs[made_number]
            logs.append(
                EpisodeLog(
                    env_indices[number],
                    requested_id,
                    env_id,
                    dict(env_kwargs),
                    reset_seeds[number],
                    student_seeds.get(number),
                    actions[number],
                    rewards[number],
                    terminated[number],
                    truncated[number],
                    options.get(number),
                )
            )
        return logs


def _split(column: list[Any], bounds: list[tuple[int, int]]) -> list[list[Any]]:
    return [column[start:end] for start, end in bounds]


_INT_KINDS = "iu"
_COLUMN_KINDS = {"rewards": "iuf", "terminated": "b", "truncated": "b"}
"""What each per-step array may hold (the actions depend on `action_form`)."""


def _check_tables(data: Any, budget: CallBudget) -> None:
    """Refuse an env table or a list of reset options longer than the call's episodes before pydantic
    validates their entries (each entry is validated; an array's steps are not)."""
    if type(data) is not dict:
        return
    options = data.get("reset_options")
    for name, table in (
        ("envs", data.get("envs")),
        ("reset_options", type(options) is dict and options.get("values")),
    ):
        if type(table) is list and len(table) > budget.max_episodes:
            raise InvalidEpisodeLogError(
                f"the episode log: {name} holds {len(table):,} entries, more than the call's limit of {budget.max_episodes:,} episodes"  # noqa: E501
            )


def _announced(log: WireLog, budget: CallBudget | None) -> tuple[int, int]:
    """`(episodes, steps)` as the arrays' specs announce them, every spec checked, no data decoded."""
    episodes = _shape(log["lengths"], "lengths", _INT_KINDS, 1)[0]
    if budget is not None and episodes > budget.max_episodes:
        raise InvalidEpisodeLogError(
            f"the log holds {episodes:,} episodes, more than the call's limit of {budget.max_episodes:,}"
        )
    steps = _shape(log["rewards"], "rewards", _COLUMN_KINDS["rewards"], 1)[0]
    if budget is not None and steps > budget.max_steps:
        raise InvalidEpisodeLogError(
            f"the log holds {steps:,} steps, more than the call's limit of {budget.max_steps:,}"
        )
    for name in ("made", "env_index", "reset_seed"):
        _shape(log[name], name, _INT_KINDS, 1, episodes)  # type: ignore[literal-required]
    for name in ("terminated", "truncated"):
        _shape(log[name], name, _COLUMN_KINDS[name], 1, steps)  # type: ignore[literal-required]
    form, actions = log["action_form"], log["actions"]
    if form == "plain":
        if type(actions) is not list or len(actions) != steps:
            raise InvalidEpisodeLogError(
                f"the episode log: actions sent as plain values should be a list of {steps:,} entries, found {describe(actions)}"  # noqa: E501
            )
    elif type(actions) is list:
        raise InvalidEpisodeLogError(
            f"the episode log: actions of form {form!r} should be an array, found a list of {len(actions):,} entries"  # noqa: E501
        )
    elif form == "int":
        _shape(actions, "actions", _INT_KINDS, 1, steps)  # type: ignore[arg-type]
    else:
        _shape(actions, "actions", "biuf", None, steps)  # type: ignore[arg-type]
    if len(log["envs"]) > max(episodes, 1):
        raise InvalidEpisodeLogError(
            f"the episode log: envs should list at most one env per episode ({episodes:,}), found {len(log['envs']):,}"  # noqa: E501
        )
    for name in ("student_seed", "reset_options"):
        sparse = log[name]  # type: ignore[literal-required]
        count = _shape(sparse["episodes"], f"{name}.episodes", _INT_KINDS, 1)[0]
        values = sparse["values"]
        found = len(values) if type(values) is list else _shape(values, f"{name}.values", _INT_KINDS, 1)[0]
        if count > episodes or found != count:
            raise InvalidEpisodeLogError(
                f"the episode log: {name} should give one value for each of at most {episodes:,} episodes, found {count:,} episodes and {found:,} values"  # noqa: E501
            )
    return episodes, steps


def _shape(
    column: TaggedArray, name: str, kinds: str, ndim: int | None, length: int | None = None
) -> list[int]:
    """The announced shape of an array, refused unless its dtype is of `kinds`, it has `ndim` dimensions
    (at least one when None) and `length` entries along the first."""
    spec = column["spec"]
    dtype, shape = spec["dtype"], spec["shape"]
    kind = np.dtype(dtype).kind if dtype in ARRAY_DTYPES else None
    dimensions_ok = len(shape) == ndim if ndim is not None else len(shape) >= 1
    if kind is None or kind not in kinds or not dimensions_ok or (length is not None and shape[0] != length):
        expected = f"{ndim}-D" if ndim is not None else "an at least 1-D"
        entries = f" of {length:,} entries" if length is not None else ""
        raise InvalidEpisodeLogError(
            f"the episode log: {name} should be {expected} array of kind {kinds!r}{entries}, found dtype {str(dtype)[:20]!r} and shape {shape}"  # noqa: E501
        )
    return shape


def _array(column: TaggedArray, name: str) -> np.ndarray:
    """The decoded array (its spec already checked by `_shape`)."""
    try:
        return decode_array(column["spec"], f"the episode log ({name})")
    except InvalidValueError as error:
        raise InvalidEpisodeLogError(error.message) from None


def _ints(column: TaggedArray, name: str, low: int, high: int) -> list[int]:
    """An int array's values as a list, refused unless each is within [low, high]."""
    array = _array(column, name)
    if array.size and (int(array.min()) < low or int(array.max()) > high):
        raise InvalidEpisodeLogError(
            f"the episode log: {name} should hold ints from {low:,} to {high:,}, found {int(array.min()):,} to {int(array.max()):,}"  # noqa: E501
        )
    values: list[int] = array.tolist()
    return values


def _positions(column: TaggedArray, name: str, episodes: int) -> list[int]:
    """The episode numbers of a sparse field: increasing, each below `episodes`."""
    positions = _ints(column, f"{name}.episodes", 0, max(episodes - 1, 0))
    if any(later <= earlier for earlier, later in itertools.pairwise(positions)):
        raise InvalidEpisodeLogError(
            f"the episode log: {name}.episodes should be strictly increasing episode numbers, found {describe(positions)}"  # noqa: E501
        )
    return positions


def _sparse_options(sparse: SparseOptions, episodes: int) -> dict[int, dict[str, Any]]:
    positions = _positions(sparse["episodes"], "reset_options", episodes)
    return {
        number: _mapping(options, f"episode {number}: reset_options")
        for number, options in zip(positions, sparse["values"], strict=True)
    }


def _actions(form: str, column: TaggedArray | list[Any], steps: int) -> list[Any]:
    """Every step's action (shape and length already checked by `_announced`)."""
    if type(column) is list:
        return _decoded(column, "actions")  # type: ignore[no-any-return]
    array = _array(column, "actions")  # type: ignore[arg-type]
    if form == "int":
        return array.tolist()  # type: ignore[no-any-return]
    return [array[step, ...] for step in range(steps)]  # one array per step, of the action's shape


def _mapping(value: dict[str, Any], where: str) -> dict[str, Any]:
    if not value:  # the common case, without a decoder's set-up
        return value
    decoded = clean_plain(_decoded(value, where))
    if type(decoded) is not dict:
        raise InvalidEpisodeLogError(f"the episode log: {where} should be a dict, found {describe(decoded)}")
    return decoded


def _decoded(value: Any, where: str) -> Any:
    """`decode_value` for one field of the log, its errors as `InvalidEpisodeLogError`."""
    try:
        return decode_value(value, f"the episode log ({where})")
    except InvalidValueError as error:
        raise InvalidEpisodeLogError(error.message) from None
