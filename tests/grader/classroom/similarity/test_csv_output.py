"""similarity.csv: the promised columns, one row per flagged pair, formulas neutralised."""

from __future__ import annotations

import csv
import io

import pytest

from grader.classroom.similarity.csv_output import COLUMNS, render_csv
from grader.classroom.similarity.report import Pair, SimilarityReport
from grader.render.neutral import safe_cell


@pytest.mark.parametrize(
    ("cell", "expected"),
    [
        ('=HYPERLINK("http://x")', '\'=HYPERLINK("http://x")'),
        ("+1", "'+1"),
        ("-2", "'-2"),
        ("@SUM(A1)", "'@SUM(A1)"),
        ("\tcmd", "'\tcmd"),
        ("\rcmd", "'\ufffdcmd"),
        ("ana", "ana"),
        ("x=1", "x=1"),
    ],
    ids=["equals", "plus", "minus", "at", "tab", "carriage return", "plain", "equals inside"],
)
def test_a_cell_a_spreadsheet_would_run_is_neutralised(cell: str, expected: str) -> None:
    assert safe_cell(cell) == expected


def test_one_row_per_flagged_pair_with_the_promised_columns() -> None:
    pair = Pair(
        a="=cmd|' /C calc'!A0",
        b="zoë",
        score=0.91234,
        shared_fingerprints=40,
        shared_fragments=3,
        longest_fragment_lines=12,
        evidence=['identical comment or text "we recieve"', "identical unusual constant 0.0173"],
    )
    report = SimilarityReport(students=["=cmd|' /C calc'!A0", "zoë"], references=0, pairs=[pair], clusters=[])
    rows = list(csv.reader(io.StringIO(render_csv(report), newline="")))
    assert rows == [
        list(COLUMNS),
        [
            "'=cmd|' /C calc'!A0",
            "zoë",
            "0.9123",
            "3",
            "12",
            'identical comment or text "we recieve" | identical unusual constant 0.0173',
        ],
    ]
