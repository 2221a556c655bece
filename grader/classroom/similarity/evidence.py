"""Evidence besides code that independent solutions rarely share: identical comments, typos, odd constants.

A comment or string (docstrings included) counts when it is long enough not to be a stock phrase, is not
the template's, and at most two documents hold it. A constant counts when it is unusual (not a round
number, not a parameter the lab gives) and equally rare. Behaviour (shared *wrong* results) comes from
`behaviour.py`; identical correct behaviour is expected and never counts.
"""

from __future__ import annotations

from grader.classroom.similarity.document import Document
from grader.classroom.similarity.frequency import Frequencies
from grader.classroom.similarity.typos import misspellings

MAX_ITEMS = 3
"""Evidence items of each kind listed per pair; the count says how many there were."""
LAB_CONSTANTS = frozenset(
    {"0.1", "0.6", "0.9", "0.5", "1e-06", "0.01", "0.001", "0.05", "0.2", "0.99", "0.95"}
)


def is_unusual(value: str) -> bool:
    """A constant few students would pick independently: not round, not one of the lab's parameters."""
    if value in LAB_CONSTANTS:
        return False
    try:
        number = float(value)
    except ValueError:
        return False
    if number.is_integer():
        magnitude = abs(int(number))
        return magnitude > 100 and magnitude % 100 not in (0, 1)
    digits = value.lower().split("e")[0].lstrip("-").replace(".", "").strip("0")
    return len(digits) >= 3


def shared_remarks(a: Document, b: Document, frequencies: Frequencies) -> list[str]:
    """The identical rare comments and strings of two documents, as the reader sees them."""
    keys = sorted(
        a.remarks.keys() & b.remarks.keys() & frequencies.rare_remarks, key=lambda key: a.remarks[key][1]
    )
    items = [
        f'identical comment or text "{_shown(a.remarks[key][0])}" ({a.identity} line {a.remarks[key][1]}, {b.identity} line {b.remarks[key][1]})'  # noqa: E501
        for key in keys
    ]
    return _capped(items, "identical comments or texts")


def shared_constants(a: Document, b: Document, frequencies: Frequencies) -> list[str]:
    """The identical unusual constants of two documents."""
    values = sorted(
        value
        for value in a.constants.keys() & b.constants.keys() & frequencies.rare_constants
        if is_unusual(value)
    )
    items = [
        f"identical unusual constant {value} ({a.identity} line {a.constants[value]}, {b.identity} line {b.constants[value]})"  # noqa: E501
        for value in values
    ]
    return _capped(items, "identical unusual constants")


def shared_typos(a: Document, b: Document, frequencies: Frequencies) -> list[str]:
    """The identical rare misspellings in two documents' comments and strings."""
    # a misspelling inside a comment both share identically is already that comment's evidence
    in_shared_remarks = {
        word
        for key in a.remarks.keys() & b.remarks.keys() & frequencies.rare_remarks
        for word in misspellings(key)
    }
    words = sorted((a.typos.keys() & b.typos.keys() & frequencies.rare_typos) - in_shared_remarks)
    items = [
        f'the same misspelling "{word}" ({a.identity} line {a.typos[word]}, {b.identity} line {b.typos[word]})'  # noqa: E501
        for word in words
    ]
    return _capped(items, "identical misspellings")


def _capped(items: list[str], kind: str) -> list[str]:
    """The first ``MAX_ITEMS`` items, and one more line counting the rest (each counts as evidence)."""
    if len(items) <= MAX_ITEMS + 1:
        return items
    return [*items[:MAX_ITEMS], f"... and {len(items) - MAX_ITEMS} more {kind}"]


def _shown(text: str) -> str:
    return text if len(text) <= 80 else text[:77] + "..."
