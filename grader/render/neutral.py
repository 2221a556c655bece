"""Hostile text made safe to show: the one place that says how every output neutralises what a student chose.

Identities, names, file names and feedback come from downloads, rosters and student code. Escaping for
HTML is the template's (Jinja autoescape) and JSON's is its encoder's; what is left is what escaping cannot
do: a name of a million characters, a right-to-left override that turns ``evil.exe\u202egpj.py`` around, a
newline that forges a line, an escape sequence that retitles a terminal, a cell a spreadsheet runs.

- one line to show (terminal lines, pages): ``display_text`` and ``display_identity`` bound a string and
  show controls and bidi overrides as U+FFFD; pages get them as the Jinja filters ``PAGE_FILTERS``
  (``grader.render.page.page_environment`` installs them in every page);
- text kept whole (CSV cells): ``inert`` shows controls (but newline and tab) and bidi overrides as U+FFFD,
  ``safe_cell`` also neutralises a formula start;
- JSON: identities kept as given (bounded the same way, so no file grows with one hostile string), its
  encoder escaping every non-ASCII character.
"""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Callable
from urllib.parse import quote, urlsplit

MAX_IDENTITY_CHARS = 256
"""Longest identity kept (JSON and page); real systems' ids and user names are far shorter."""
MAX_NAME_CHARS = 120
MAX_DIAGNOSIS_CHARS = 400
"""Characters of a diagnosis' normalised feedback kept (its key) and shown."""
MAX_NOTE_CHARS = 300
MAX_HREF_CHARS = 2_000
IDENTITY_SHOWN_CHARS = 80
"""Characters of an identity a page or a terminal line shows (JSON keeps up to ``MAX_IDENTITY_CHARS``)."""
MAX_LINE_CHARS = 2_000
"""Characters of a reason or note a terminal line shows."""
ELLIPSIS = "…"

HIDDEN = "\ufffd"
"""Shown in place of a control, bidi override or unassigned character: visibly there, doing nothing."""
HIDDEN_CATEGORIES = frozenset({"Cc", "Cs", "Co", "Cn"})
"""Controls, surrogates, private-use and unassigned characters: shown as ``HIDDEN`` everywhere."""
BLANK = "(blank)"
BIDI_CONTROLS = frozenset("\u061c\u200e\u200f\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069")
"""Characters that reorder the text around them (Unicode TR9 explicit formatting); never shown."""


def bounded(text: str, limit: int) -> str:
    """``text`` cut to at most ``limit`` characters, the cut marked with an ellipsis.

    Args:
        text: Any string.
        limit: The most characters returned (at least 1).

    Returns:
        ``text`` when short enough, else its first ``limit - 1`` characters and ``…``.
    """
    if len(text) <= limit:
        return text
    return text[: limit - 1] + ELLIPSIS


def display_text(text: str, limit: int) -> str:
    """``text`` as one line to show: controls and bidi overrides shown as ``\ufffd``, whitespace collapsed,
    bounded.

    Args:
        text: A student identity, name, note or feedback: any string.
        limit: The most characters returned.

    Returns:
        The cleaned, bounded text (HTML escaping is still the template's job).
    """
    return _cleaned(text, limit, HIDDEN_CATEGORIES)


def terminal_line(text: str) -> str:
    """A printed line that holds names a student chose: its leading indentation kept, the rest as
    ``display_text`` (``MAX_LINE_CHARS``), so no name can retitle or clear the terminal or start a line."""
    indent = text[: len(text) - len(text.lstrip(" "))]
    return indent + display_text(text, MAX_LINE_CHARS)


def display_block(text: str) -> str:
    """Multi-line text to show as it is (a traceback, what a program printed, a feedback): as
    ``display_text`` for every control but the line break and the tab (ESC, BEL, a lone carriage return,
    DEL and the C1 controls), every bidi override and every surrogate, private-use or unassigned character,
    each shown as ``\ufffd``; lines, tabs and every other character kept, a CRLF read as a line break. Not
    bounded: reports bound their feedback and output where they are made.

    What the text summary of `gymgrade check` prints and what Gradescope's results carry pass through it,
    so no escape sequence a student's code printed or raised reaches a terminal or a page.
    """
    if text.isascii() and not _ASCII_CONTROLS.search(text):
        return text
    return "".join(
        character if character in _KEPT_IN_BLOCKS
        else HIDDEN if character in BIDI_CONTROLS or unicodedata.category(character) in HIDDEN_CATEGORIES
        else character
        for character in text.replace("\r\n", "\n")
    )  # fmt: skip


_KEPT_IN_BLOCKS = frozenset("\n\t")
_ASCII_CONTROLS = re.compile("[\x00-\x08\x0b-\x1f\x7f]")


def display_identity(text: str, limit: int) -> str:
    """An identity to show: as ``display_text``, and every invisible format character (zero-width space,
    joiners, soft hyphen, byte order mark) also shown as ``\ufffd``, so two identities that differ only
    by one never look alike; a blank identity reads ``(blank)``.

    Names keep their joiners (scripts such as Persian and Devanagari need them); ids never do.
    """
    return _cleaned(text, limit, HIDDEN_CATEGORIES | {"Cf"}) or BLANK


def _cleaned(text: str, limit: int, hidden: frozenset[str]) -> str:
    # Cut first (bounded work on huge input), then clean, then cut again to the exact bound.
    rough = text[: limit * 4]
    shown = "".join(
        " " if character.isspace()
        else HIDDEN if character in BIDI_CONTROLS or unicodedata.category(character) in hidden
        else character
        for character in rough
    )  # fmt: skip
    single = " ".join(shown.split())
    return bounded(single if len(rough) == len(text) else single + ELLIPSIS, limit)


INERT_CATEGORIES = frozenset({"Cc", "Cs"})
"""Controls and surrogates: shown as ``HIDDEN`` even in text kept whole (newline and tab excepted)."""
KEPT_CONTROLS = frozenset("\n\t")
FORMULA_STARTS = frozenset("=+-@")
"""A spreadsheet runs a cell as a formula when, after leading blanks and invisible characters, it starts with
one of these, or with a character NFKC-equal to one (fullwidth ``＝``, small ``﹦``, superscript ``⁺``)."""


def inert(text: str) -> str:
    """``text`` kept whole (lines and length), every control but newline and tab, every surrogate and every
    bidi override shown as ``\ufffd``: what a CSV cell or a multi-line text holds of a hostile string."""
    if text.isprintable():  # every character replaced below is unprintable: the common case costs one scan
        return text
    return "".join(
        HIDDEN
        if character not in KEPT_CONTROLS
        and (character in BIDI_CONTROLS or unicodedata.category(character) in INERT_CATEGORIES)
        else character
        for character in text
    )


MAX_FILE_NAME_CHARS = 120
"""Characters of a submitted file's own name shown (the longest a common file system allows is 255 bytes)."""


def file_name(name: str) -> str:
    """A submitted file's own name as a person reads it: the last component of its path in the download
    (``/`` or ``\\`` separated, so ``../`` shows nothing of where it claims to be), as ``display_text``
    (``MAX_FILE_NAME_CHARS``), with an apostrophe before a formula start as in ``safe_cell``; ``(blank)``
    when nothing is left. Only ever shown: it never names anything on disk.

    Args:
        name: The name (or ``/``-separated path) the student or the LMS gave the file: any string.

    Returns:
        One bounded line, e.g. ``smithjohn_12345_678_policy_iteration-1.py``.
    """
    leaf = name.replace("\\", "/").rstrip("/").rsplit("/", 1)[-1]
    shown = display_text(leaf, MAX_FILE_NAME_CHARS) or BLANK
    return "'" + bounded(shown, MAX_FILE_NAME_CHARS - 1) if _runs_as_formula(shown) else shown


def safe_cell(value: object) -> str:
    """A spreadsheet cell's text: ``inert``, with an apostrophe before a start that a spreadsheet would run
    (``=``, ``+``, ``-``, ``@``, a leading tab or carriage return, any of them after blanks, or their
    fullwidth and small forms).

    Numbers we write ourselves (``-0.5`` never happens: scores are >= 0) pass through as text unchanged.
    """
    text = "" if value is None else str(value)
    return "'" + inert(text) if _runs_as_formula(text) else inert(text)


def _runs_as_formula(text: str) -> bool:
    if text.startswith(("\t", "\r")):
        return True
    for character in text[:1_000]:
        if character.isspace() or unicodedata.category(character) in ("Cc", "Cf"):
            continue
        return unicodedata.normalize("NFKC", character)[:1] in FORMULA_STARTS
    return False


def safe_href(href: str | None) -> str | None:
    """A relative link to a student's report, percent-encoded, or None when it is not a plain relative path.

    Refused: schemes (``javascript:``, ``data:``, ``http:``), absolute and protocol-relative paths,
    backslashes, query strings and controls; a refused link is shown as plain text, never followed.

    Args:
        href: The link as given (a path relative to the page, ``/``-separated), or None.

    Returns:
        The encoded link, or None.
    """
    if not href or len(href) > MAX_HREF_CHARS or "\\" in href or href.startswith("/"):
        return None
    if any(unicodedata.category(character) in ("Cc", "Cf", "Cs", "Co", "Zl", "Zp") for character in href):
        return None
    parts = urlsplit(href)
    if parts.scheme or parts.netloc or parts.query or parts.fragment or ":" in href.split("/")[0]:
        return None
    return quote(href, safe="/")


PAGE_FILTERS: dict[str, Callable[[str], str]] = {
    "identity": lambda text: display_identity(text, IDENTITY_SHOWN_CHARS),
    "document": lambda text: display_identity(text, MAX_IDENTITY_CHARS),
    "name": lambda text: display_text(text, MAX_NAME_CHARS),
    "note": lambda text: display_text(text, MAX_NOTE_CHARS),
    "line": lambda text: display_text(text, MAX_LINE_CHARS),
    "code": inert,
}
"""What every page shows of hostile text, by Jinja filter (``{{ row.identity|identity }}``,
``{{ line|code }}``): an identity (80 characters), a compared document's name (a student's identity or a
reference file's path, 256), a name, a note, a longer line of text, a line of code kept whole."""
