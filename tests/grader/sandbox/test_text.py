"""Strings from the child are cleaned at the boundary (grader/sandbox/text.py)."""

from __future__ import annotations

import json

import pytest

from grader.sandbox.child.frames import parse_payload
from grader.sandbox.text import clean_plain, clean_text

SURROGATE = chr(0xD800)


@pytest.mark.parametrize(
    ("text", "limit", "expected"),
    [
        ("plain", 10, "plain"),
        ("é and 😀", 10, "é and 😀"),
        (f"a{SURROGATE}b\x00c", 10, "a\ufffdb\ufffdc"),
        ("x" * 12, 10, "xxxxxxxxxx\n[... 2 more characters cut]"),
        (f"{SURROGATE}" * 3 + "tail", 2, "\ufffd\ufffd\n[... 5 more characters cut]"),
    ],
    ids=["ascii", "non-ascii-kept", "surrogate-and-nul", "capped", "capped-and-cleaned"],
)
def test_clean_text(text: str, limit: int, expected: str) -> None:
    cleaned = clean_text(text, limit)

    assert cleaned == expected
    cleaned.encode("utf-8")


def test_json_escapes_become_clean_plain_data() -> None:
    payload = b'{"\\ud800key": ["\\udfff", {"nested\\u0000": "\\ud83d\\ude00 kept"}], "n": 1.5}'

    cleaned = clean_plain(parse_payload(payload))

    assert cleaned == {"\ufffdkey": ["\ufffd", {"nested\ufffd": "😀 kept"}], "n": 1.5}
    json.dumps(cleaned, ensure_ascii=False).encode("utf-8")


def test_clean_plain_keeps_clean_containers() -> None:
    value = {"a": [1, "b", {"c": None}]}

    assert clean_plain(value) is value
    assert value == {"a": [1, "b", {"c": None}]}
