"""Hostile identities, names and links: bounded, controls and bidi overrides inert, links only relative."""

from __future__ import annotations

import pytest

from grader.render.neutral import (
    BLANK,
    ELLIPSIS,
    HIDDEN,
    bounded,
    display_identity,
    display_text,
    inert,
    safe_href,
    terminal_line,
)


@pytest.mark.parametrize(
    ("text", "limit", "shown"),
    [
        ("alice", 80, "alice"),
        ("evil\u202egpj.py", 80, f"evil{HIDDEN}gpj.py"),
        ("\u2067\u05e9\u05dc\u05d5\u05dd\u2069 x", 80, f"{HIDDEN}\u05e9\u05dc\u05d5\u05dd{HIDDEN} x"),
        ("a\u200fb\u061cc\u200ed", 80, f"a{HIDDEN}b{HIDDEN}c{HIDDEN}d"),
        ("line\nbreak\r\tand\u2028more", 80, "line break and more"),
        ("nul\x00bell\x07esc\x1b[31m", 80, f"nul{HIDDEN}bell{HIDDEN}esc{HIDDEN}[31m"),
        ("Zoë Ñúñez 王小明", 80, "Zoë Ñúñez 王小明"),
        ("x" * 1_000_000, 80, "x" * 79 + ELLIPSIS),
        ("x" * 81, 80, "x" * 79 + ELLIPSIS),
        ("x" * 80, 80, "x" * 80),
        ("\u202e" * 1_000_000, 10, HIDDEN * 9 + ELLIPSIS),
    ],
    ids=["plain", "rtl-override", "rtl-isolates", "marks", "line-breaks", "terminal-escapes", "unicode-names",
         "a-million-chars", "one-too-many", "exactly-the-limit", "a-million-overrides"],
)  # fmt: skip
def test_display_text_is_one_bounded_line_with_every_control_inert(text: str, limit: int, shown: str) -> None:
    assert display_text(text, limit) == shown


@pytest.mark.parametrize(
    ("identity", "shown"),
    [
        ("alice\u200b", f"alice{HIDDEN}"),
        ("\ufeffbob", f"{HIDDEN}bob"),
        ("car\u00adol", f"car{HIDDEN}ol"),
        ("da\u200dve", f"da{HIDDEN}ve"),
        ("", BLANK),
        (" \n\t ", BLANK),
        ("0042", "0042"),
    ],
    ids=[
        "zero-width-space",
        "byte-order-mark",
        "soft-hyphen",
        "joiner",
        "empty",
        "whitespace",
        "leading-zeros",
    ],
)
def test_identities_that_differ_invisibly_look_different(identity: str, shown: str) -> None:
    assert display_identity(identity, 80) == shown


def test_names_keep_the_joiners_their_scripts_need() -> None:
    persian = "\u0645\u06cc\u200c\u062e\u0648\u0627\u0647\u0645"
    assert display_text(persian, 80) == persian
    assert display_identity(persian, 80) != persian


def test_bounded_keeps_text_as_given_up_to_its_limit() -> None:
    assert bounded("0042\u202e", 5) == "0042\u202e"
    assert bounded("abcdef", 3) == "ab" + ELLIPSIS


@pytest.mark.parametrize(
    ("href", "safe"),
    [
        ("alice.json", "alice.json"),
        ("reports/0042.json", "reports/0042.json"),
        ("../out/bob smith.json", "../out/bob%20smith.json"),
        ("o'brien\"><script>.json", "o%27brien%22%3E%3Cscript%3E.json"),
        ("ünï.json", "%C3%BCn%C3%AF.json"),
        ("javascript:alert(1)", None),
        ("JaVaScRiPt:alert(1)", None),
        ("data:text/html,<script>alert(1)</script>", None),
        ("https://evil.example/x", None),
        ("//evil.example/x", None),
        ("/etc/passwd", None),
        ("..\\..\\secret", None),
        ("a.json?x=1", None),
        ("a.json#frag", None),
        ("java\tscript:alert(1)", None),
        ("a\u202e.json", None),
        ("a\nb.json", None),
        ("", None),
        (None, None),
        ("x" * 5_000, None),
    ],
    ids=lambda value: repr(value)[:24],
)
def test_only_plain_relative_links_survive_and_they_are_percent_encoded(
    href: str | None, safe: str | None
) -> None:
    assert safe_href(href) == safe


@pytest.mark.parametrize(
    ("text", "kept"),
    [
        ("two\nlines\tand a tab", "two\nlines\tand a tab"),
        ("Zoë Ñúñez 王小明", "Zoë Ñúñez 王小明"),
        ("ali\x1b]0;owned\x07ce", f"ali{HIDDEN}]0;owned{HIDDEN}ce"),
        ("\x9b31mx\r", f"{HIDDEN}31mx{HIDDEN}"),
        ("\u202eecila", f"{HIDDEN}ecila"),
        ("lone \ud800 surrogate", f"lone {HIDDEN} surrogate"),
    ],
    ids=["newline-and-tab", "unicode", "escape-and-bell", "c1-and-cr", "rtl-override", "surrogate"],
)
def test_inert_keeps_text_whole_but_controls_and_overrides(text: str, kept: str) -> None:
    assert inert(text) == kept
    assert len(inert(text)) == len(text)


@pytest.mark.parametrize(
    ("line", "printed"),
    [
        ("  alice: rl1: imports gymnasium", "  alice: rl1: imports gymnasium"),
        ("  eve\n  refused alice: forged", "  eve refused alice: forged"),
        ("\x1b[2J\x1b]0;owned\x07mallory", f"{HIDDEN}[2J{HIDDEN}]0;owned{HIDDEN}mallory"),
    ],
    ids=["plain", "forged-line", "clear-and-retitle"],
)
def test_a_terminal_line_keeps_its_indent_and_nothing_a_name_could_do(line: str, printed: str) -> None:
    assert terminal_line(line) == printed
