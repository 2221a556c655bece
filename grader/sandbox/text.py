"""Strings from the child, made safe once where they enter the parent: no lone surrogates, no NULs, capped.

`json.loads` turns the escape `"\\ud800"` into a lone surrogate, which no UTF-8 encoder accepts (the
report's `model_dump_json()` raises on it), and `"\\u0000"` into a NUL, which databases and terminals
mishandle. Every string a child sends passes through `clean_text` (messages, output, names, compat
events, env ids) or `clean_plain` (return values, env arguments, reset options) before it reaches a
`CallOutcome`, so nothing downstream needs to care.
"""

from __future__ import annotations

import re
from typing import Any

MESSAGE_CHARS = 20_000
"""Characters kept of a message or a traceback."""
EVENT_CHARS = 500
"""Characters kept of each field of a compat event."""
NAME_CHARS = 200
"""Characters kept of a function or parameter name."""
REPLACEMENT = "\ufffd"
_UNSAFE = re.compile("[\x00\ud800-\udfff]")


def clean_text(text: str, limit: int) -> str:
    """`text` with lone surrogates and NULs replaced by U+FFFD, cut to `limit` characters with a note.

    Args:
        text: A string from the child.
        limit: Characters to keep; the rest is replaced by a note saying how many were cut.

    Returns:
        A string that encodes as UTF-8.
    """
    if len(text) > limit:
        text = f"{text[:limit]}\n[... {len(text) - limit:,} more characters cut]"
    if text.isascii() and "\x00" not in text:
        return text
    return _UNSAFE.sub(REPLACEMENT, text)


def clean_plain(value: Any) -> Any:
    """Plain data (as `decode_value` builds it) with every string, dict keys included, cleaned in place.

    Strings are not cut: the frame's limits already bound them. Containers are the caller's own fresh
    objects, so lists are changed in place; a dict is rebuilt only when one of its keys changes.
    """
    kind = type(value)
    if kind is str:
        return clean_text(value, len(value))
    if kind is list:
        for index, item in enumerate(value):
            if type(item) in _CLEANED:
                value[index] = clean_plain(item)
        return value
    if kind is dict:
        for key, item in value.items():
            if type(item) in _CLEANED:
                value[key] = clean_plain(item)
        if not all(map(_is_clean, value)):
            return {clean_text(key, len(key)): item for key, item in value.items()}
        return value
    return value


_CLEANED = frozenset({str, list, dict})


def _is_clean(text: str) -> bool:
    return (text.isascii() and "\x00" not in text) or _UNSAFE.search(text) is None
