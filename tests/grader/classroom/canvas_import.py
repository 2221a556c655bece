"""Canvas's gradebook CSV import, re-implemented from its documentation to check what we upload.

What Canvas's guides say about importing a gradebook CSV ("How do I import grades in the Gradebook?"):
- the file is CSV (UTF-8; a byte-order mark is tolerated);
- the first row names the columns; the student columns are ``Student``, ``ID``, ``SIS User ID``,
  ``SIS Login ID`` and ``Section`` (as an export has them); a student is matched by ``ID`` (Canvas's user id)
  when it is given, else by SIS User ID / SIS Login ID;
- an assignment column is named ``{title} ({assignment id})``; a column whose name carries no id in
  parentheses creates a new assignment (not what an upload of scores should do);
- a row whose ``Student`` cell reads ``Points Possible`` (an export indents it with spaces) carries the
  points, is read-only and is skipped;
- a score is a number, or empty (nothing changes), or EX (excused); anything else is refused;
- a row whose student is not in the course is refused.
"""

from __future__ import annotations

import csv
import io
import re

REQUIRED = ("Student", "ID", "SIS User ID", "SIS Login ID", "Section")
ASSIGNMENT = re.compile(r"^(?P<title>.+) \((?P<id>\d+)\)$")


class CanvasImportError(ValueError):
    """Raised where Canvas's importer would refuse the file or a row of it."""


def canvas_import(
    text: str, students: set[str], assignments: dict[str, float]
) -> dict[tuple[str, str], float | str]:
    """Apply a gradebook CSV as Canvas would: the scores it sets, by (user id, assignment id)."""
    rows = list(csv.reader(io.StringIO(text.lstrip("\ufeff"), newline="")))
    if not rows:
        raise CanvasImportError("empty file")
    header = rows[0]
    missing = [column for column in REQUIRED if column not in header]
    if missing:
        raise CanvasImportError(f"missing columns {missing}")
    columns: dict[int, str] = {}
    for index, name in enumerate(header):
        if name in REQUIRED:
            continue
        match = ASSIGNMENT.match(name)
        if match is None:
            raise CanvasImportError(
                f"column {name!r} names no assignment id: Canvas would create an assignment"
            )
        if match["id"] not in assignments:
            raise CanvasImportError(f"assignment {match['id']} is not in the course")
        columns[index] = match["id"]
    changes: dict[tuple[str, str], float | str] = {}
    id_column = header.index("ID")
    for row in rows[1:]:
        if len(row) != len(header):
            raise CanvasImportError(f"row {row} has {len(row)} cells, the header {len(header)}")
        if row[0].strip() == "Points Possible":
            continue
        user = row[id_column]
        if user not in students:
            raise CanvasImportError(f"student {user!r} is not in the course")
        for index, assignment in columns.items():
            cell = row[index].strip()
            if cell == "":
                continue
            if cell == "EX":
                changes[(user, assignment)] = "EX"
                continue
            try:
                score = float(cell)
            except ValueError:
                raise CanvasImportError(f"score {cell!r} of {user} is not a number") from None
            changes[(user, assignment)] = score
    return changes
