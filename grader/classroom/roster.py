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

    @property
    def keys(self) -> frozenset[str]:
        """Every id the roster gives them, case-folded: any of them joins a submission to them."""
        return frozenset(self.fields[column].casefold() for column in ID_COLUMNS if self.fields.get(column))

    def get(self, column: str) -> str:
        """A column's value ("" when absent)."""
        return self.fields.get(column, "")


class Roster:
    """The students of a roster, found by any of their ids."""

    def __init__(self, entries: list[RosterEntry]) -> None:
        self.entries = entries
        self._by_key: dict[str, RosterEntry] = {}
        for entry in entries:
            for key in entry.keys:
                self._by_key.setdefault(key, entry)

    def find(self, identity: str) -> RosterEntry | None:
        """The student whose ids include ``identity`` (case-insensitively), None when none does."""
        return self._by_key.get(identity.casefold())


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
    return Roster(entries)


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
