"""Frames and plain-data encoding: round trips, and everything untrusted that must be refused."""

from __future__ import annotations

import io
import json
import math
import pickle
import struct
from typing import Any

import numpy as np
import pytest

from grader.sandbox.child import frames
from grader.sandbox.child.errors import FrameTooLargeError, InvalidValueError, ProtocolError


class RiggedFloat(float):
    """A float that claims to equal and exceed everything."""

    def __eq__(self, other: object) -> bool:
        return True

    def __ge__(self, other: object) -> bool:
        return True

    __hash__ = float.__hash__


class RiggedInt(int):
    def __eq__(self, other: object) -> bool:
        return True

    __hash__ = int.__hash__


class StrSubclass(str):
    pass


class ListSubclass(list):  # type: ignore[type-arg]
    pass


def wire(value: Any) -> Any:
    """Encode, pass through a real frame, decode: what the parent sees."""
    frame = frames.encode_frame({"type": "value", "value": frames.encode_value(value)})
    message = frames.read_frame(io.BytesIO(frame))
    assert message is not None
    return frames.decode_value(message["value"])


ROUND_TRIPS = [
    (None, None),
    (True, True),
    (0, 0),
    (-(2**200), -(2**200)),
    (0.1, 0.1),
    ("ünïcode", "ünïcode"),
    ([1, [2.5, "x"], {"a": None}], [1, [2.5, "x"], {"a": None}]),
    ((1, 2), [1, 2]),
    ({"nested": {"deep": [True, False]}}, {"nested": {"deep": [True, False]}}),
    (np.float32(0.5), 0.5),
    (np.int64(-7), -7),
    (np.uint8(255), 255),
    (np.bool_(True), True),
]


@pytest.mark.parametrize(
    ("value", "expected"),
    ROUND_TRIPS,
    ids=[f"{index}-{type(value).__name__}" for index, (value, _) in enumerate(ROUND_TRIPS)],
)
def test_plain_values_round_trip_with_exact_types(value: Any, expected: Any) -> None:
    decoded = wire(value)

    assert decoded == expected
    assert type(decoded) is type(expected)


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf], ids=["nan", "inf", "-inf"])
def test_non_finite_floats_are_tagged_and_restored(value: float) -> None:
    encoded = frames.encode_value(value)
    decoded = wire(value)

    assert encoded == {"$float": repr(value)}
    assert type(decoded) is float
    assert (math.isnan(decoded) and math.isnan(value)) or decoded == value


ARRAYS = [
    np.arange(12, dtype=np.int64).reshape(3, 4),
    np.linspace(-1, 1, 7, dtype=np.float32),
    np.array([True, False]),
    np.zeros((0, 3), dtype=np.uint16),
    np.array(3.25),
    np.arange(6, dtype=">i4").reshape(2, 3),
    np.asfortranarray(np.arange(6.0).reshape(2, 3)),
    np.array([np.nan, np.inf, -0.0]),
]


@pytest.mark.parametrize("array", ARRAYS, ids=lambda a: f"{a.dtype.str}{list(a.shape)}")
def test_numeric_arrays_round_trip_bit_for_bit(array: np.ndarray) -> None:
    decoded = wire(array)

    assert type(decoded) is np.ndarray
    assert decoded.dtype == array.dtype
    assert decoded.shape == array.shape
    assert decoded.tobytes() == np.ascontiguousarray(array).tobytes()
    assert decoded.flags.writeable


REFUSED = [
    (RiggedFloat(0.9), "RiggedFloat, a subclass of float"),
    (RiggedInt(1), "RiggedInt, a subclass of int"),
    (StrSubclass("x"), "StrSubclass, a subclass of str"),
    (ListSubclass([1]), "ListSubclass, a subclass of list"),
    ([1, RiggedFloat(2.0)], "the value[1] is not plain data"),
    ({"win": RiggedFloat(0.4)}, "the value['win'] is not plain data"),
    (np.array([1, "a"], dtype=object), "dtype object"),
    (np.array([1 + 2j]), "dtype complex128"),
    (np.array(["text"]), "dtype <U4"),
    (np.ma.array([1.0]), "MaskedArray"),
    (b"bytes", "found builtins.bytes"),
    (pickle.dumps({"a": 1}), "found builtins.bytes"),
    (bytearray(b"x"), "found builtins.bytearray"),
    ({1: "int key"}, "dict key of type int"),
    ({"$float": "nan"}, "keys may not start with '$'"),
    ({1, 2}, "found builtins.set"),
    (object(), "found builtins.object"),
    (lambda: 0, "found builtins.function"),
    (2**300, "bits, more than 256"),
]


@pytest.mark.parametrize(
    ("value", "message"),
    REFUSED,
    ids=[f"{index}-{type(value).__name__}" for index, (value, _) in enumerate(REFUSED)],
)
def test_values_that_are_not_exactly_plain_are_refused_with_their_type(value: Any, message: str) -> None:
    with pytest.raises(InvalidValueError) as caught:
        frames.encode_value(value, "the value")

    assert message in caught.value.message
    assert "is not plain data" in caught.value.message


def test_refusal_message_names_the_function_and_the_fix() -> None:
    with pytest.raises(InvalidValueError) as caught:
        frames.encode_value(RiggedFloat(0.4), "the value returned by blackjack()")

    assert caught.value.message == (
        "the value returned by blackjack() is not plain data: found test_frames.RiggedFloat, a subclass of "
        "float; subclasses are refused because they can change comparisons; only plain data can be returned: "
        "None, bool, int, float, str, list, tuple, dict with str keys, numpy numbers and numpy arrays of "
        "bool/int/float; convert it with `float(...)`"
    )


@pytest.mark.slow
def test_huge_lists_are_refused() -> None:
    with pytest.raises(InvalidValueError, match="more than 2000000 elements"):
        frames.encode_value([0] * (frames.MAX_NODES + 1))


def test_deep_nesting_and_cycles_are_refused() -> None:
    deep: list[Any] = []
    for _ in range(frames.MAX_DEPTH + 5):
        deep = [deep]
    cycle: list[Any] = []
    cycle.append(cycle)

    for value in (deep, cycle):
        with pytest.raises(InvalidValueError, match="nested more than 64 levels"):
            frames.encode_value(value)


DECODE_REFUSED = [
    ({"$pickle": "gASV"}, "unknown tagged object"),
    ({"$float": "1.5"}, "unknown tagged object"),
    ({"$ndarray": {"dtype": "|O", "shape": [1], "data": "AA=="}}, "not a bool/int/float dtype"),
    (
        {"$ndarray": {"dtype": "<f8", "shape": [2], "data": "AAAAAAAAAAA="}},
        "data of 12 characters cannot hold",
    ),
    ({"$ndarray": {"dtype": "<f8", "shape": [1], "data": "AAAAAAAAAA=="}}, "array data has 7 bytes"),
    ({"$ndarray": {"dtype": "<f8", "shape": [-1], "data": ""}}, "not a list of non-negative ints"),
    ({"$ndarray": {"dtype": "<f8", "shape": [1], "data": "!!!!!!!!!!!!"}}, "not valid base64"),
    (
        {"$ndarray": {"dtype": "<f8", "shape": [1], "data": "AA==", "extra": 1}},
        "exactly dtype, shape and data",
    ),
    ({"$ndarray": {"dtype": "<f8", "shape": [1.0], "data": ""}}, "not a list of non-negative ints"),
    ({"ok": {"$float": "nan", "x": 1}}, "unknown tagged object"),
]


@pytest.mark.parametrize(
    ("data", "message"), DECODE_REFUSED, ids=[json.dumps(data)[:48] for data, _ in DECODE_REFUSED]
)
def test_decoding_refuses_forged_tagged_objects(data: Any, message: str) -> None:
    with pytest.raises(InvalidValueError, match=message):
        frames.decode_value(data)


def test_decoding_refuses_too_deep_data() -> None:
    deep: Any = 0
    for _ in range(frames.MAX_DEPTH + 2):
        deep = [deep]

    with pytest.raises(InvalidValueError, match="too large or too deeply nested"):
        frames.decode_value(deep)


def frame(payload: bytes) -> io.BytesIO:
    return io.BytesIO(struct.pack(">I", len(payload)) + payload)


FRAME_ERRORS = [
    (frame(b'{"a": NaN}'), "not valid UTF-8 JSON"),
    (frame(b'{"a": Infinity}'), "not valid UTF-8 JSON"),
    (frame(b'{"a": 1e400}'), "not valid UTF-8 JSON"),
    (frame(b'{"a": 1, "a": 2}'), "duplicate keys"),
    (frame(b"[1, 2]"), "must hold a JSON object, found list"),
    (frame(b"\xff\xfe{}"), "not valid UTF-8 JSON"),
    (frame(pickle.dumps({"type": "result"})), "not valid UTF-8 JSON"),
    (frame(b"[" * 100_000 + b"]" * 100_000), "not valid UTF-8 JSON"),
    (frame(b'{"a": 1'), "not valid UTF-8 JSON"),
    (io.BytesIO(b"\x00\x00"), "ended after 2 of 4 bytes"),
    (io.BytesIO(struct.pack(">I", 10) + b"{}"), "ended after 2 of 10 bytes"),
]


@pytest.mark.parametrize(
    ("stream", "message"), FRAME_ERRORS, ids=[repr(stream.getvalue()[:24]) for stream, _ in FRAME_ERRORS]
)
def test_malformed_frames_are_refused(stream: io.BytesIO, message: str) -> None:
    with pytest.raises(ProtocolError, match=message):
        frames.read_frame(stream)


def test_oversized_frames_are_refused_before_reading_the_payload() -> None:
    stream = io.BytesIO(struct.pack(">I", 2**31) + b"{}")

    with pytest.raises(FrameTooLargeError, match="2147483648 bytes exceeds the limit of 1024"):
        frames.read_frame(stream, max_frame=1024)


def test_encoding_a_frame_over_the_limit_is_refused() -> None:
    with pytest.raises(FrameTooLargeError):
        frames.encode_frame({"data": "x" * 2048}, max_frame=1024)


def test_frames_follow_each_other_and_end_cleanly() -> None:
    stream = io.BytesIO(frames.encode_frame({"n": 1}) + frames.encode_frame({"n": 2}))

    assert frames.read_frame(stream) == {"n": 1}
    assert frames.read_frame(stream) == {"n": 2}
    assert frames.read_frame(stream) is None
