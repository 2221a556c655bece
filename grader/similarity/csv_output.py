"""``similarity.csv``: one row per flagged pair, safe to open in a spreadsheet."""

from __future__ import annotations

import csv
import io

from grader.similarity.report import SimilarityReport

COLUMNS = ("a", "b", "score", "shared_fragments", "longest_fragment_lines", "evidence")
FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")
"""A spreadsheet runs a cell starting with one of these as a formula; names and comments are untrusted."""


def neutralised(cell: str) -> str:
    """The cell, with a leading apostrophe when a spreadsheet would run it as a formula (CSV injection)."""
    return "'" + cell if cell.startswith(FORMULA_STARTS) else cell


def render_csv(report: SimilarityReport) -> str:
    """The CSV text (UTF-8 once written; the caller writes it with ``newline=""``)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\r\n")
    writer.writerow(COLUMNS)
    for pair in report.pairs:
        writer.writerow(
            [
                neutralised(pair.a),
                neutralised(pair.b),
                f"{pair.score:.4f}",
                str(pair.shared_fragments),
                str(pair.longest_fragment_lines),
                neutralised(" | ".join(pair.evidence)),
            ]
        )
    return buffer.getvalue()
