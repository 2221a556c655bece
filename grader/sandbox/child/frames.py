"""Frames and plain-data encoding shared by the sandbox runner (parent) and the child harness.

A frame is a 4-byte big-endian length followed by that many bytes of UTF-8 JSON holding one object.
Values travel as JSON with two tagged forms: ``{"$float": "nan" | "inf" | "-inf"}`` for non-finite
floats and ``{"$ndarray": {"dtype": "<f8", "shape": [...], "data": base64}}`` for numeric numpy
arrays (raw bytes read back with `numpy.frombuffer`, never pickle). Only exact built-in types are
accepted: a subclass of `float` with rigged comparisons is refused, not converted. A call's arguments may
also hold ``{"$env": {"id": ..., "max_episode_steps": ..., "form": ..., "kwargs": {...}}}`` (`EnvArgument`):
an environment the child passes to the call by name or makes for it (the learners of edition rl1 take `env`,
the second lab's `run_simulation(env, policy, beta)` a FrozenLake env of the grader's); no return value or
episode log may. A call's arguments may also hold ``{"$mdp": {"name": ..., "table": ...}}``
(`MdpArgument`): a finite MDP in the second lab's format, carried as plain lists and handed to the call as
a fresh `{state: {action: [(probability, next_state, reward, terminal), ...]}}` (int keys, tuples), which
a str-keyed frame cannot carry.
"""

from __future__ import annotations

import base64
import binascii
import contextlib
import gc
import json
import math
import os
import struct
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any, BinaryIO

import numpy as np

from grader.sandbox.child.errors import FrameTooLargeError, InvalidValueError, ProtocolError

HEADER = struct.Struct(">I")
DEFAULT_MAX_FRAME = 256 * 1024 * 1024
MAX_DEPTH = 64
MAX_NODES = 2_000_000
MAX_INT_BITS = 256
FLOAT_TAG = "$float"
NDARRAY_TAG = "$ndarray"
ENV_TAG = "$env"
MAX_ENV_ID = 100
MDP_TAG = "$mdp"
MAX_MDP_STATES = 4096
MAX_MDP_ACTIONS = 64
MAX_MDP_OUTCOMES = 200_000
"""Bounds of a decoded `MdpArgument`: states, actions per state, outcomes over the whole table (FrozenLake
8x8 slippery has 64, 4 and 768)."""
MAX_MDP_NAME = 200

PLAIN_TYPES_HINT = "only plain data can be returned: None, bool, int, float, str, list, tuple, dict with str keys, numpy numbers and numpy arrays of bool/int/float"  # noqa: E501
_NON_FINITE = {"nan": math.nan, "inf": math.inf, "-inf": -math.inf}
_INTEGER_SCALARS = ("int8", "int16", "int32", "int64", "uint8", "uint16", "uint32", "uint64", "longlong")
_NUMPY_SCALARS: dict[type, Callable[[Any], Any]] = {
    np.bool_: bool,
    np.ulonglong: int,
    **{getattr(np, name): int for name in _INTEGER_SCALARS},
    **{getattr(np, name): float for name in ("float16", "float32", "float64", "longdouble")},
}
_ARRAY_KINDS = frozenset("biuf")
ARRAY_DTYPES = frozenset(
    np.dtype(code).newbyteorder(order).str
    for code in ("?", "i1", "i2", "i4", "i8", "u1", "u2", "u4", "u8", "f2", "f4", "f8")
    for order in ("<", ">")
)
"""The dtypes (`dtype.str`) an array may have on the wire: bool, int, uint and float, either byte order."""


ENV_OBJECT = "object"
"""`EnvArgument.form`: the child makes the env (through the recorder) and passes the object."""
ENV_NAME = "name"
"""`EnvArgument.form`: the child passes the id (a str); the env the function makes by that name during the
call gets `max_episode_steps` and is recorded like any other (the lab's `env = gym.make(env)`)."""
ENV_NAME_OR_OBJECT = "name_or_object"
"""`EnvArgument.form`: the name first; when the call fails on it before making or playing any env, it is
made again with the env object (a student who changed the function to take one), and a compat event of
kind `env_object` says so."""
ENV_GYM_OBJECT = "gym_object"
"""`EnvArgument.form`: the child makes the env as `ENV_OBJECT` does and passes it behind the compatibility
layer's `gym` API (`grader.compat.ClassicEnv`), which serves each call site the API its code expects
(classic gym's `obs = env.reset()` and four-value `step`, or gym 0.26/gymnasium's two and five values): the
second lab's `run_simulation(env, ...)` is written for the gym of its edition."""
ENV_FORMS = (ENV_OBJECT, ENV_NAME, ENV_NAME_OR_OBJECT, ENV_GYM_OBJECT)
ENV_KWARG_NAMES = frozenset({"map_name", "is_slippery"})
"""Constructor arguments an `EnvArgument` may carry (FrozenLake's map and slipperiness); values are plain
str, bool or int."""


@dataclass(frozen=True)
class EnvArgument:
    """An argument the child replaces by an environment's name or by an env it makes and records.

    Attributes:
        env_id: The id (a lab id such as ``"Taxi-v3"`` is resolved as the compat layer does).
        max_episode_steps: The time limit of the env made (by the child, or by the function from the
            name); None keeps the registered one.
        form: One of `ENV_FORMS`: how the env reaches the function.
        kwargs: Constructor arguments of the env made (`ENV_KWARG_NAMES`), as sorted (name, value) pairs.
    """

    env_id: str
    max_episode_steps: int | None = None
    form: str = ENV_OBJECT
    kwargs: tuple[tuple[str, str | bool | int], ...] = ()

    def __repr__(self) -> str:
        if self.form not in (ENV_OBJECT, ENV_GYM_OBJECT):
            return repr(self.env_id)
        arguments = "".join(f", {name}={value!r}" for name, value in self.kwargs)
        return f"gym.make({self.env_id!r}{arguments})"


MdpOutcome = tuple[float, int, float, bool]
"""One entry of `P[s][a]`: (probability, next state, reward, terminal)."""


@dataclass(frozen=True)
class MdpArgument:
    """An argument the child replaces by a fresh copy of a finite MDP's table, in the second lab's format.

    Attributes:
        name: How messages name it (e.g. "FrozenLake 4x4 (slippery)"); not passed to the function.
        table: `table[s][a]` lists the outcomes (probability, next state, reward, terminal) in order; every
            state has the same number of actions.
    """

    name: str
    table: tuple[tuple[tuple[MdpOutcome, ...], ...], ...]

    def __repr__(self) -> str:
        return f"<P of {self.name}>"

    @property
    def n_states(self) -> int:
        """`nS`."""
        return len(self.table)

    @property
    def n_actions(self) -> int:
        """`nA`."""
        return len(self.table[0]) if self.table else 0

    def as_table(self) -> dict[int, dict[int, list[MdpOutcome]]]:
        """What the function receives: `{s: {a: [(p, s', r, done), ...]}}`, a new copy at every call (python
        ints, floats and bools), so what one call does to it never reaches the next."""
        return {
            state: {action: list(outcomes) for action, outcomes in enumerate(actions)}
            for state, actions in enumerate(self.table)
        }


@contextlib.contextmanager
def paused_gc() -> Iterator[None]:
    """Pause the cyclic garbage collector for the block (restored afterwards, even if it was off).

    Encoding, parsing and decoding a frame of episode logs builds millions of small objects that form
    no cycles; every automatic collection meanwhile rescans all of them (and every other live
    object), which made parsing a 2-million-step Taxi log 6x slower. Nothing is lost by collecting later.
    """
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def encode_frame(message: dict[str, Any], max_frame: int = DEFAULT_MAX_FRAME) -> bytes:
    """Serialise one message (already plain JSON data) into a length-prefixed frame.

    Raises:
        FrameTooLargeError: the encoded message is longer than `max_frame` bytes.
    """
    with paused_gc():
        payload = json.dumps(message, allow_nan=False, separators=(",", ":")).encode()
    if len(payload) > max_frame:
        raise FrameTooLargeError(len(payload), max_frame)
    return HEADER.pack(len(payload)) + payload


def write_frame(fd: int, message: dict[str, Any], max_frame: int = DEFAULT_MAX_FRAME) -> None:
    """Write one frame to a raw file descriptor, looping over partial writes."""
    view = memoryview(encode_frame(message, max_frame))
    while view:
        written = os.write(fd, view)
        view = view[written:]


def read_frame(stream: BinaryIO, max_frame: int = DEFAULT_MAX_FRAME) -> dict[str, Any] | None:
    """Read one frame; return None on a clean end of stream before a header.

    Raises:
        FrameTooLargeError: the header announces more than `max_frame` bytes.
        ProtocolError: the stream ends inside a frame or the payload is not a JSON object.
    """
    header = _read_exactly(stream, HEADER.size, allow_eof=True)
    if header is None:
        return None
    (size,) = HEADER.unpack(header)
    if size > max_frame:
        raise FrameTooLargeError(size, max_frame)
    payload = _read_exactly(stream, size, allow_eof=False)
    if payload is None:
        raise ProtocolError("the stream ended inside a frame")
    return parse_payload(payload)


def parse_payload(payload: bytes) -> dict[str, Any]:
    """Parse a frame payload strictly: UTF-8 JSON object, no NaN literals, no duplicate keys."""
    try:
        with paused_gc():
            message = json.loads(
                payload.decode("utf-8"),
                parse_constant=_refuse_constant,
                parse_float=_finite_float,
                object_pairs_hook=_unique_keys,
            )
    except (UnicodeDecodeError, ValueError, RecursionError) as error:
        raise ProtocolError(f"a frame is not valid UTF-8 JSON: {error}") from None
    if type(message) is not dict:
        raise ProtocolError(f"a frame must hold a JSON object, found {type(message).__name__}")
    return message


def encode_value(value: Any, what: str = "the value", max_bytes: int | None = None) -> Any:
    """Encode plain data into JSON-ready data, refusing anything that is not exactly plain.

    Args:
        value: the value to send.
        what: how to name the value in error messages, e.g. "the return value of blackjack()".
        max_bytes: refuse values whose strings and arrays alone would need more bytes than this
            (checked before any array is copied into base64).

    Raises:
        InvalidValueError: a type other than the exact plain types, a dict key that is not a
            str, an oversized int, too deep nesting or too many elements.
        FrameTooLargeError: the value exceeds `max_bytes`.
    """
    with paused_gc():
        return _Encoder(what, max_bytes).encode(value, "", 0)


def decode_value(data: Any, what: str = "the value", *, allow_envs: bool = False) -> Any:
    """Decode data produced by `encode_value` (after JSON parsing), validating every node.

    Args:
        data: The parsed JSON.
        what: How to name the value in error messages.
        allow_envs: Accept `EnvArgument` and `MdpArgument` tags (a call's arguments only, never a returned
            value).

    Raises:
        InvalidValueError: the data does not have the layout `encode_value` produces.
    """
    with paused_gc():
        return _Decoder(what, allow_envs).decode(data, "", 0)


def decode_array(spec: Any, what: str = "the array") -> np.ndarray:
    """Decode the payload of one ``{"$ndarray": spec}`` tag, as `decode_value` would (for many arrays).

    Raises:
        InvalidValueError: `spec` is not a dict with a bool/int/float dtype, a shape and base64 data of
            exactly that size (checked before decoding).
    """
    if type(spec) is not dict:
        raise _invalid(what, "", "an array's payload must be a dict")
    return _decode_array(spec, what, "")


class _Encoder:
    def __init__(self, what: str, max_bytes: int | None) -> None:
        self.what = what
        self.nodes = 0
        self.max_bytes = max_bytes
        self.bytes = 0

    def spend(self, size: int) -> None:
        self.bytes += size
        if self.max_bytes is not None and self.bytes > self.max_bytes:
            raise FrameTooLargeError(self.bytes, self.max_bytes)

    def encode(self, value: Any, where: str, depth: int) -> Any:
        self.nodes += 1
        if self.nodes > MAX_NODES:
            raise _invalid(self.what, where, f"it has more than {MAX_NODES} elements; return less data")
        if depth > MAX_DEPTH:
            raise _invalid(self.what, where, f"it is nested more than {MAX_DEPTH} levels deep")
        kind = type(value)
        if kind is str:
            self.spend(len(value))
            return value
        if value is None or kind is bool:
            return value
        if kind is int:
            return _checked_int(value, self.what, where)
        if kind is float:
            return value if math.isfinite(value) else {FLOAT_TAG: _non_finite_name(value)}
        if kind is list or kind is tuple:
            return [self.encode(item, f"{where}[{index}]", depth + 1) for index, item in enumerate(value)]
        if kind is dict:
            return self._encode_dict(value, where, depth)
        if kind is np.ndarray:
            self.spend(value.nbytes * 4 // 3)
            return _encode_array(value, self.what, where)
        if kind in _NUMPY_SCALARS:
            return self.encode(_NUMPY_SCALARS[kind](value), where, depth)
        if kind is MdpArgument:
            return {
                MDP_TAG: {
                    "name": value.name,
                    "table": [
                        [[[p, s, r, done] for p, s, r, done in outcomes] for outcomes in actions]
                        for actions in value.table
                    ],
                }
            }
        if kind is EnvArgument:
            return {
                ENV_TAG: {
                    "id": value.env_id,
                    "max_episode_steps": value.max_episode_steps,
                    "form": value.form,
                    "kwargs": dict(value.kwargs),
                }
            }
        raise _invalid(self.what, where, _found(value) + "; " + PLAIN_TYPES_HINT + _conversion_hint(value))

    def _encode_dict(self, value: dict[Any, Any], where: str, depth: int) -> dict[str, Any]:
        encoded: dict[str, Any] = {}
        for key, item in value.items():
            if type(key) is not str:
                raise _invalid(
                    self.what, where, f"it has a dict key of type {type(key).__name__}; use str keys"
                )
            if key.startswith("$"):
                raise _invalid(self.what, where, f"it has the dict key {key!r}; keys may not start with '$'")
            encoded[key] = self.encode(item, f"{where}[{key!r}]", depth + 1)
        return encoded


class _Decoder:
    def __init__(self, what: str, allow_envs: bool = False) -> None:
        self.what = what
        self.nodes = 0
        self.allow_envs = allow_envs

    def decode(self, data: Any, where: str, depth: int) -> Any:
        self.nodes += 1
        if self.nodes > MAX_NODES or depth > MAX_DEPTH:
            raise _invalid(self.what, where, "it is too large or too deeply nested")
        kind = type(data)
        if data is None or kind is bool or kind is str:
            return data
        if kind is int:
            return _checked_int(data, self.what, where)
        if kind is float:
            if not math.isfinite(data):
                raise _invalid(self.what, where, "a non-finite float was not tagged")
            return data
        if kind is list:
            return [self.decode(item, f"{where}[{index}]", depth + 1) for index, item in enumerate(data)]
        if kind is not dict:
            raise _invalid(self.what, where, f"found {kind.__name__}, which JSON cannot produce")
        if any(key.startswith("$") for key in data):
            return self._decode_tagged(data, where)
        return {key: self.decode(item, f"{where}[{key!r}]", depth + 1) for key, item in data.items()}

    def _decode_tagged(self, data: dict[str, Any], where: str) -> Any:
        if data.keys() == {FLOAT_TAG} and data[FLOAT_TAG] in _NON_FINITE:
            return _NON_FINITE[data[FLOAT_TAG]]
        if data.keys() == {NDARRAY_TAG} and type(data[NDARRAY_TAG]) is dict:
            return _decode_array(data[NDARRAY_TAG], self.what, where)
        if self.allow_envs and data.keys() == {ENV_TAG}:
            return _decode_env(data[ENV_TAG], self.what, where)
        if self.allow_envs and data.keys() == {MDP_TAG}:
            return _decode_mdp(data[MDP_TAG], self.what, where)
        raise _invalid(self.what, where, f"unknown tagged object with keys {sorted(data)}")


def _decode_env(spec: Any, what: str, where: str) -> EnvArgument:
    if type(spec) is not dict or spec.keys() != {"id", "max_episode_steps", "form", "kwargs"}:
        raise _invalid(what, where, "an env argument needs exactly id, max_episode_steps, form and kwargs")
    env_id, limit, form, kwargs = spec["id"], spec["max_episode_steps"], spec["form"], spec["kwargs"]
    if type(kwargs) is not dict or not set(kwargs) <= ENV_KWARG_NAMES:
        raise _invalid(what, where, f"an env argument's kwargs are a dict of {sorted(ENV_KWARG_NAMES)}")
    if any(type(value) not in (str, bool, int) for value in kwargs.values()):
        raise _invalid(what, where, "an env argument's kwargs hold str, bool or int values only")
    if type(form) is not str or form not in ENV_FORMS:
        raise _invalid(what, where, f"an env argument's form must be one of {', '.join(ENV_FORMS)}")
    if type(env_id) is not str or not 0 < len(env_id) <= MAX_ENV_ID:
        raise _invalid(what, where, f"an env id must be a string of 1 to {MAX_ENV_ID} characters")
    if limit is not None and (type(limit) is not int or not 0 < limit < 2**62):
        raise _invalid(what, where, f"max_episode_steps {limit!r} is not a positive int or null")
    return EnvArgument(env_id, limit, form, tuple(sorted(kwargs.items())))


def _decode_mdp(spec: Any, what: str, where: str) -> MdpArgument:
    """A `MdpArgument` from its wire form, every node checked and the whole bounded before it is built."""
    if type(spec) is not dict or spec.keys() != {"name", "table"}:
        raise _invalid(what, where, "an MDP argument needs exactly name and table")
    name, rows = spec["name"], spec["table"]
    if type(name) is not str or not 0 < len(name) <= MAX_MDP_NAME:
        raise _invalid(what, where, f"an MDP's name must be a string of 1 to {MAX_MDP_NAME} characters")
    if type(rows) is not list or not 0 < len(rows) <= MAX_MDP_STATES:
        raise _invalid(what, where, f"an MDP's table must list 1 to {MAX_MDP_STATES} states")
    width = len(rows[0]) if type(rows[0]) is list else 0
    if not 0 < width <= MAX_MDP_ACTIONS:
        raise _invalid(what, where, f"an MDP's states must list 1 to {MAX_MDP_ACTIONS} actions")
    outcomes = 0
    table = []
    for state, actions in enumerate(rows):
        if type(actions) is not list or len(actions) != width:
            raise _invalid(what, f"{where}[{state}]", f"every state must list the same {width} actions")
        built = []
        for action, listed in enumerate(actions):
            if type(listed) is not list:
                raise _invalid(what, f"{where}[{state}][{action}]", "an action's outcomes must be a list")
            outcomes += len(listed)
            if outcomes > MAX_MDP_OUTCOMES:
                raise _invalid(what, where, f"an MDP may hold at most {MAX_MDP_OUTCOMES} outcomes")
            built.append(
                tuple(_mdp_outcome(item, len(rows), what, f"{where}[{state}][{action}]") for item in listed)
            )
        table.append(tuple(built))
    return MdpArgument(name, tuple(table))


def _mdp_outcome(item: Any, n_states: int, what: str, where: str) -> MdpOutcome:
    if type(item) is not list or len(item) != 4:
        raise _invalid(what, where, "an outcome is [probability, next_state, reward, terminal]")
    probability, next_state, reward, done = item
    numbers = (probability, reward)
    if not all(type(number) in (int, float) and math.isfinite(number) for number in numbers):
        raise _invalid(what, where, "an outcome's probability and reward must be finite numbers")
    if not 0 <= probability <= 1:
        raise _invalid(what, where, f"an outcome's probability {probability!r} is not in [0, 1]")
    if type(next_state) is not int or not 0 <= next_state < n_states:
        raise _invalid(what, where, f"an outcome's next state {next_state!r} is not in 0..{n_states - 1}")
    if type(done) is not bool:
        raise _invalid(what, where, "an outcome's terminal flag must be a bool")
    return (float(probability), next_state, float(reward), done)


def _encode_array(array: np.ndarray, what: str, where: str) -> dict[str, Any]:
    if array.dtype.kind not in _ARRAY_KINDS or array.dtype.str not in ARRAY_DTYPES:
        raise _invalid(
            what,
            where,
            f"found a numpy array of dtype {array.dtype}; "
            "only bool, int, uint and float arrays can be returned (convert with `.astype(float)`, or return a list)",  # noqa: E501
        )
    if array.ndim > MAX_DEPTH:
        raise _invalid(what, where, f"the array has {array.ndim} dimensions")
    data = base64.b64encode(np.ascontiguousarray(array).tobytes()).decode("ascii")
    return {NDARRAY_TAG: {"dtype": array.dtype.str, "shape": list(array.shape), "data": data}}


def _decode_array(spec: dict[str, Any], what: str, where: str) -> np.ndarray:
    if spec.keys() != {"dtype", "shape", "data"}:
        raise _invalid(what, where, f"an array needs exactly dtype, shape and data, found {sorted(spec)}")
    dtype_name, shape, data = spec["dtype"], spec["shape"], spec["data"]
    if type(dtype_name) is not str or dtype_name not in ARRAY_DTYPES:
        raise _invalid(what, where, f"array dtype {dtype_name!r} is not a bool/int/float dtype")
    if (
        type(shape) is not list
        or len(shape) > MAX_DEPTH
        or not all(type(size) is int and 0 <= size < 2**62 for size in shape)
    ):
        raise _invalid(what, where, f"array shape {shape!r} is not a list of non-negative ints")
    if type(data) is not str:
        raise _invalid(what, where, "array data must be a base64 string")
    dtype = np.dtype(dtype_name)
    size = math.prod(shape) * dtype.itemsize
    if len(data) != 4 * ((size + 2) // 3):  # checked before decoding: the shape bounds the work
        raise _invalid(
            what, where, f"array data of {len(data)} characters cannot hold shape {shape} of {dtype}"
        )
    try:
        raw = base64.b64decode(data.encode("ascii"), validate=True)
    except (binascii.Error, UnicodeEncodeError):
        raise _invalid(what, where, "array data is not valid base64") from None
    if len(raw) != math.prod(shape) * dtype.itemsize:
        raise _invalid(
            what, where, f"array data has {len(raw)} bytes, shape {shape} of {dtype} needs more or less"
        )
    return np.frombuffer(bytearray(raw), dtype=dtype).reshape(shape)


def _checked_int(value: int, what: str, where: str) -> int:
    if value.bit_length() > MAX_INT_BITS:
        raise _invalid(what, where, f"an int has {value.bit_length()} bits, more than {MAX_INT_BITS}")
    return value


def _invalid(what: str, where: str, detail: str) -> InvalidValueError:
    location = f"{what}{where}" if where else what
    return InvalidValueError(f"{location} is not plain data: {detail}", where)


def _found(value: Any) -> str:
    kind = type(value)
    plain_bases = [
        base.__name__ for base in (bool, int, float, str, list, tuple, dict) if isinstance(value, base)
    ]
    if plain_bases:
        return (
            f"found {kind.__module__}.{kind.__qualname__}, a subclass of {plain_bases[0]}; "
            f"subclasses are refused because they can change comparisons"
        )
    if isinstance(value, np.generic):
        return f"found numpy scalar of dtype {value.dtype}"
    return f"found {kind.__module__}.{kind.__qualname__}"


def _conversion_hint(value: Any) -> str:
    for base in (float, int, str, list, dict):
        if isinstance(value, base):
            return f"; convert it with `{base.__name__}(...)`"
    return ""


def _non_finite_name(value: float) -> str:
    if math.isnan(value):
        return "nan"
    return "inf" if value > 0 else "-inf"


def _read_exactly(stream: BinaryIO, size: int, *, allow_eof: bool) -> bytes | None:
    chunks: list[bytes] = []
    remaining = size
    while remaining:
        chunk = stream.read(remaining)
        if not chunk:
            if allow_eof and remaining == size:
                return None
            raise ProtocolError(f"the stream ended after {size - remaining} of {size} bytes")
        chunks.append(chunk)
        remaining -= len(chunk)
    return b"".join(chunks)


def _refuse_constant(name: str) -> Any:
    raise ValueError(f"the JSON constant {name} is not allowed")


def _finite_float(text: str) -> float:
    number = float(text)
    if not math.isfinite(number):
        raise ValueError(f"the number {text} is out of range")
    return number


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    result = dict(pairs)
    if len(result) != len(pairs):
        raise ValueError("duplicate keys in a JSON object")
    return result
