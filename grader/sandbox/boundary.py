"""How data from the child is validated: declared pydantic models in strict mode, errors a person can read.

Everything the child sends is untrusted. `episode_log.WireLog` and the frame models in `messages`
declare what it may send; this module holds what they share: the strict configuration, unions that fail
with one message, and the conversion of a `ValidationError` into one readable sentence (what was expected,
where, what was found).
"""

from __future__ import annotations

import reprlib
from collections.abc import Sequence
from typing import Any, cast

import numpy as np
from pydantic import BeforeValidator, ConfigDict, GetPydanticSchema, ValidationError
from pydantic_core import PydanticCustomError, core_schema

STRICT = ConfigDict(strict=True, extra="forbid")
"""Exact JSON types (no bool where an int is expected, no str for a number) and no undeclared fields."""
SHOWN_CHARS = 60
"""Characters of a refused value quoted in a message."""
_REPR = reprlib.Repr()
_REPR.maxstring = _REPR.maxother = SHOWN_CHARS  # a bounded repr, however large the refused value


def at_most(limit: int) -> BeforeValidator:
    """Refuse a list or dict of more than `limit` entries before any entry is validated.

    Pydantic's `max_length` is checked after the entries, so a forged frame could make it validate
    millions of them first. Use as `Annotated[list[X], at_most(100)]`.
    """

    def check(value: Any) -> Any:
        if type(value) in (list, dict) and len(value) > limit:
            raise PydanticCustomError(
                "too_long",
                "should hold at most {limit} entries, found {found}",
                {"limit": limit, "found": len(value)},
            )
        return value

    return BeforeValidator(check)


def one_of(expected: str) -> GetPydanticSchema:
    """Make a union fail with `expected` ("must be a list of ints or an int array") instead of one error
    per alternative. Use as `Annotated[A | B, Field(union_mode="left_to_right"), one_of("...")]`."""

    def schema(source: Any, handler: Any) -> core_schema.CoreSchema:
        union: dict[str, Any] = handler(source)
        if union["type"] != "union":
            raise TypeError(f"one_of() applies to a union, found a {union['type']} schema")
        union["custom_error_type"] = "one_of"
        union["custom_error_message"] = expected
        return cast(core_schema.CoreSchema, union)

    return GetPydanticSchema(schema)


def problem(error: ValidationError, where: str, skip: int = 0) -> str:
    """The first problem of `error` as one sentence: where it is, what was expected, what was found.

    Args:
        error: What pydantic refused.
        where: What was validated ("the ready frame", "episode 3").
        skip: Leading entries of the error's location already said by `where` (a list index).
    """
    first = error.errors(include_url=False)[0]
    parts = first["loc"][skip:]
    if first["type"] == "missing":
        return f"{_place(where, parts[:-1])}: the field {parts[-1]!r} is missing"
    if first["type"] == "extra_forbidden":
        return f"{_place(where, parts[:-1])}: {parts[-1]!r} is not one of its fields"
    if first["type"] == "too_long":
        return f"{_place(where, parts)}: {first['msg']}"
    return f"{_place(where, parts)}: {_lowered(first['msg'])}, found {describe(first['input'])}"


def describe(value: Any) -> str:
    """A refused value in a few words: its type and the start of its repr (arrays by dtype and shape)."""
    if type(value) is np.ndarray:
        return f"an array of dtype {value.dtype} and shape {value.shape}"
    return f"{type(value).__name__} {_REPR.repr(value)[:SHOWN_CHARS]}"


def _place(where: str, parts: Sequence[int | str]) -> str:
    path = "".join(f"[{part}]" if type(part) is int else f".{part}" for part in parts).lstrip(".")
    return f"{where}: {path}" if path else where


def _lowered(message: str) -> str:
    """Pydantic's "Input should be ..." reads as "should be ..." after a location."""
    return message.removeprefix("Input ")
