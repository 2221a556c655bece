"""Write one `## ...` section of bench/RESULTS.md: the benches' `--write`."""

from __future__ import annotations

import re
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "RESULTS.md"


def replace_section(heading: str, text: str) -> None:
    """Replace the section that starts with the line ``heading`` by ``text`` (append it when absent)."""
    current = RESULTS.read_text(encoding="utf-8")
    pattern = re.compile(rf"^{re.escape(heading)}\n.*?(?=^## |\Z)", re.MULTILINE | re.DOTALL)
    updated = (
        pattern.sub(lambda _: text, current) if pattern.search(current) else current.rstrip() + "\n\n" + text
    )
    RESULTS.write_text(updated, encoding="utf-8")
