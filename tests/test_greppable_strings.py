"""Messages people read are greppable: no string literal of grader/ or api/ is split mid-phrase.

Implicit concatenation ("the car did not reach " "the flag") hides a phrase from grep. Every part of an
implicitly concatenated run of literals but the last must end at a sentence or clause boundary: ". ",
": ", "; ", "\\n", or the end of a sentence ("." "!" "?" with or without a trailing space; "e.g. " ends
none). Runs of markup (SVG elements starting with "<", a stylesheet starting with a CSS rule) are split
between elements and attributes and are not messages.
"""

from __future__ import annotations

import io
import re
import tokenize
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCANNED = ("grader", "api")
_PREFIX = re.compile(r"(?is)^[a-z]*('''|\"\"\"|'|\")")
_BOUNDARY = re.compile(r"([.!?:;] ?|\\n|\n)$")
_ABBREVIATION = re.compile(r"\b(e\.g|i\.e|etc|vs)\. ?$")
_MARKUP = re.compile(r"^(<|[\w.#,:\- ]+\{)")


def _body(literal: str) -> str:
    """The source text between a literal's quotes (escapes and f-string fields as written)."""
    match = _PREFIX.match(literal)
    if match is None:
        raise ValueError(f"expected a string literal, found {literal!r}")
    return literal[match.end() : -len(match.group(1))]


def concatenated_runs(source: str) -> list[list[tokenize.TokenInfo]]:
    """Every run of two or more adjacent string literals (comments and line breaks between them allowed)."""
    runs: list[list[tokenize.TokenInfo]] = []
    current: list[tokenize.TokenInfo] = []
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type == tokenize.STRING:
            current.append(token)
        elif token.type not in (tokenize.NL, tokenize.COMMENT):
            if len(current) > 1:
                runs.append(current)
            current = []
    return runs


def split_mid_phrase(source: str) -> list[tuple[int, str]]:
    """(line, end of the part) for each part of a prose run that does not end at a boundary."""
    found = []
    for literals in concatenated_runs(source):
        if _MARKUP.match(_body(literals[0].string)):
            continue
        for literal in literals[:-1]:
            body = _body(literal.string)
            if not _BOUNDARY.search(body) or _ABBREVIATION.search(body):
                found.append((literal.start[0], body[-40:]))
    return found


@pytest.mark.parametrize(
    ("source", "expected"),
    [
        ('x = ("the car did not reach " "the flag")', [(1, "the car did not reach ")]),
        ('x = (f"{n} steps. " "Push along the velocity.")', []),
        ('x = ("expected a table: " f"found {shape}")', []),
        ('x = ("line one\\n" "line two")', []),
        ('x = ("lasted "  # why\n     f"{n} steps " "in all")', [(1, "lasted "), (2, "{n} steps ")]),
        ("x = ('<rect x=\"1\" ' 'fill=\"none\"/>')", []),
        ('x = ("body{margin:0}" ".meta{color:#555}")', []),
        ('x = "one whole literal"', []),
        ('x = ("abandoned (e.g. " f"episode {n})")', [(1, "abandoned (e.g. ")]),
    ],
    ids=[
        "mid-phrase",
        "sentence",
        "clause",
        "newline",
        "comment-between",
        "svg",
        "css",
        "single",
        "abbreviation",
    ],
)
def test_the_scan_tells_a_phrase_split_from_a_clause_boundary(
    source: str, expected: list[tuple[int, str]]
) -> None:
    assert split_mid_phrase(source) == expected


def test_no_message_of_grader_or_api_is_split_mid_phrase() -> None:
    files = sorted(path for folder in SCANNED for path in (ROOT / folder).rglob("*.py"))
    assert files, "found no sources under grader/ and api/"
    split = [
        f"{path.relative_to(ROOT)}:{line}: ...{end!r}"
        for path in files
        for line, end in split_mid_phrase(path.read_text(encoding="utf-8"))
    ]
    assert split == [], (
        "rejoin these literals into one per sentence or clause (a long literal may carry `# noqa: E501`):\n"
        + "\n".join(split)
    )
