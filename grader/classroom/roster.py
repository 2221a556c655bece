"""Rosters: a CSV naming the class (GitHub Classroom's roster, a Canvas gradebook export, or any CSV with
id / name / email columns), joined to submissions by any id it gives a student."""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from pathlib import Path

from grader.classroom.errors import RosterError

MAX_ROSTER_BYTES = 16 * 2**20
ID_COLUMNS = (
    "id", "github_username", "identifier", "sis user id", "sis login id", "sid", "student id", "student_id",
    "username", "user", "login", "participant id", "email", "email address", "github_id",
)  # fmt: skip
"""Columns whose values name a student, in order of preference for the row's identity."""


KEY_COLUMNS: dict[str, tuple[str, ...]] = {
    "plain": ("username", "login", "sis login id", "student id", "student_id", "sid", "user"),
    "canvas": ("id",),
    "github-classroom": ("github_username",),
    "gradescope": ("sid", "student id", "student_id"),
    "moodle": ("participant id", "id"),
    "nbgrader": ("student id", "student_id", "username", "id"),
    "blackboard": ("username", "user", "login", "sis login id"),
}
"""The roster column a layout's identities are matched on (the first the roster has): one key per layout,
never any column, so that one student's id cannot equal another column of another student's row (a GitHub
username that is someone's roster identifier). Plain folders are named by the instructor, most often by login:
its list is logins first. A roster with none of a layout's columns is matched on its first `ID_COLUMNS`
column; an identity with an ``@`` matches the email column (`EMAIL_LAYOUTS`)."""
EMAIL_COLUMNS = ("email", "email address")
EMAIL_LAYOUTS = ("gradescope", "plain")
"""Layouts whose identities may be emails (Gradescope's submitters without an SID, folders named by email):
an identity with an ``@`` matches the email column there."""
_ASCII_UPPER = str.maketrans("ABCDEFGHIJKLMNOPQRSTUVWXYZ", "abcdefghijklmnopqrstuvwxyz")


def roster_key(identity: str) -> str:
    """An id as the course systems compare it: ASCII letters case-insensitively (GitHub usernames, logins,
    emails), everything else exactly. Unicode case folding is not applied: a Kelvin sign (U+212A) is not a K
    to any of them, so ``\u212aim`` never matches ``kim``."""
    return identity.strip().translate(_ASCII_UPPER)


@dataclass(frozen=True)
class RosterEntry:
    """A student on the roster.

    Attributes:
        identity: Their preferred id (the first of ``ID_COLUMNS`` they have).
        name: Their name ("" if the roster gives none).
        email: Their email ("" if none).
        fields: Every column of their row, by lower-cased header.
    """

    identity: str
    name: str
    email: str
    fields: dict[str, str]

    def get(self, column: str) -> str:
        """A column's value ("" when absent)."""
        return self.fields.get(column, "")


class Roster:
    """The students of a roster, found by the one column a layout's identities are matched on."""

    def __init__(self, entries: list[RosterEntry], columns: tuple[str, ...] = ()) -> None:
        self.entries = entries
        self.columns = columns or tuple(dict.fromkeys(c for entry in entries for c in entry.fields))
        self._by_column: dict[str, dict[str, RosterEntry]] = {}

    def key_column(self, layout: str, identity: str = "") -> str | None:
        """The column identities of ``layout`` are matched on (None: the roster has no id column)."""
        by_email = "@" in identity and layout in EMAIL_LAYOUTS
        wanted = EMAIL_COLUMNS if by_email else KEY_COLUMNS.get(layout, ())
        return next((column for column in (*wanted, *ID_COLUMNS) if column in self.columns), None)

    def find(self, identity: str, layout: str = "plain") -> RosterEntry | None:
        """The student whose value in the layout's key column is ``identity`` (`roster_key` of both), None
        when none is. Of two rows with the same key, the first counts."""
        column = self.key_column(layout, identity)
        if column is None:
            return None
        if column not in self._by_column:
            index: dict[str, RosterEntry] = {}
            for entry in self.entries:
                if entry.get(column):
                    index.setdefault(roster_key(entry.get(column)), entry)
            self._by_column[column] = index
        return self._by_column[column].get(roster_key(identity))


def parse_roster(text: str, *, source: str = "roster") -> Roster:
    """Read a roster CSV's text.

    Raises:
        RosterError: No header, or no column that names students (the message lists what it looked for).
    """
    reader = csv.DictReader(io.StringIO(text.lstrip("\ufeff")))
    if not reader.fieldnames:
        raise RosterError(f"{source} is empty: expected a CSV with a header row")
    headers = [header.strip().casefold() for header in reader.fieldnames]
    if not any(column in headers for column in ID_COLUMNS):
        raise RosterError(
            f"{source} has columns {', '.join(reader.fieldnames)}; expected one naming students: "
            f"{', '.join(ID_COLUMNS)} (GitHub Classroom's roster, a Canvas gradebook export, or your own CSV)"
        )
    entries: list[RosterEntry] = []
    for row in reader:
        fields = {
            header.strip().casefold(): (value or "").strip()
            for header, value in row.items()
            if isinstance(header, str) and isinstance(value, str)
        }
        if fields.get("student", "").strip().lower() == "points possible":
            continue
        identity = next((fields[column] for column in ID_COLUMNS if fields.get(column)), "")
        if not identity:
            continue
        name = (
            fields.get("name")
            or fields.get("student")
            or " ".join(part for part in (fields.get("first name", ""), fields.get("last name", "")) if part)
        )
        email = fields.get("email") or fields.get("email address") or ""
        entries.append(RosterEntry(identity, name, email, fields))
    return Roster(entries, tuple(headers))


def read_roster(path: Path) -> Roster:
    """Read a roster CSV file (UTF-8, a BOM allowed).

    Raises:
        RosterError: It cannot be read, is too large, or names no students.
    """
    try:
        data = path.read_bytes()
    except OSError as error:
        raise RosterError(f"cannot read the roster {path} ({error.strerror}): pass a CSV file") from error
    if len(data) > MAX_ROSTER_BYTES:
        raise RosterError(
            f"the roster {path} is {len(data):,} bytes, over {MAX_ROSTER_BYTES:,}: is it a roster?"
        )
    try:
        return parse_roster(data.decode("utf-8"), source=str(path))
    except UnicodeDecodeError as error:
        raise RosterError(f"the roster {path} is not UTF-8 text ({error}): export it as CSV UTF-8") from error
    except csv.Error as error:
        raise RosterError(f"the roster {path} is not a readable CSV ({error})") from error
