"""Write one section of bench/RESULTS.md: the benches' `--write`.

A bench writes its section with a `## Title` heading; RESULTS.md files it under an area, where it may stand
one level deeper (`### Title`). The section is found by its title at either level, replaced up to the next
heading of the same or a higher level, and written at the level it stands at (its own sub-headings shifted
alike); a title not found yet is appended at the end, as the bench wrote it.
"""

from __future__ import annotations

import re
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "RESULTS.md"


def _shifted(text: str, levels: int) -> str:
    """`text` with every Markdown heading made `levels` levels deeper."""
    if levels <= 0:
        return text
    return re.sub(r"^(#{2,5}) ", lambda m: "#" * (len(m.group(1)) + levels) + " ", text, flags=re.MULTILINE)


def replace_section(heading: str, text: str) -> None:
    """Replace the section titled as ``heading`` (``## Title``) by ``text`` (append it when absent)."""
    current = RESULTS.read_text(encoding="utf-8")
    title = heading.lstrip("#").strip()
    found = re.search(rf"^(#{{2,3}}) {re.escape(title)}\n", current, re.MULTILINE)
    if found is None:
        RESULTS.write_text(current.rstrip() + "\n\n" + text, encoding="utf-8")
        return
    level = len(found.group(1))
    end = re.compile(rf"^#{{2,{level}}} ", re.MULTILINE).search(current, found.end())
    stop = end.start() if end is not None else len(current)
    replacement = _shifted(text, level - 2).rstrip("\n") + "\n\n"
    RESULTS.write_text(current[: found.start()] + replacement + current[stop:].lstrip("\n"), encoding="utf-8")
