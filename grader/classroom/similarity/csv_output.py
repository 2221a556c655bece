"""``similarity.csv``: one row per flagged pair, safe to open in a spreadsheet (every cell through
``grader.render.neutral.safe_cell``, as the gradebooks')."""

from __future__ import annotations

import csv
import io

from grader.classroom.similarity.report import SimilarityReport
from grader.render.neutral import safe_cell

COLUMNS = ("a", "b", "score", "shared_fragments", "longest_fragment_lines", "evidence")


def render_csv(report: SimilarityReport) -> str:
    """The CSV text (UTF-8 once written; the caller writes it with ``newline=""``)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\r\n")
    writer.writerow(COLUMNS)
    for pair in report.pairs:
        writer.writerow(
            [
                safe_cell(pair.a),
                safe_cell(pair.b),
                f"{pair.score:.4f}",
                str(pair.shared_fragments),
                str(pair.longest_fragment_lines),
                safe_cell(" | ".join(pair.evidence)),
            ]
        )
    return buffer.getvalue()
