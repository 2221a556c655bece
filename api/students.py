"""Creating students and looking them up."""

from __future__ import annotations

import unicodedata

from sqlalchemy import select
from sqlalchemy.exc import IntegrityError
from sqlalchemy.orm import Session

from api.errors import InvalidStudentName, StudentExists, StudentNotFound
from api.models import Student
from api.security import new_token, token_digest

MAX_NAME_CHARS = 100


def normalise_name(name: str) -> str:
    """Validate a student name and return it trimmed.

    Raises:
        InvalidStudentName: Empty, longer than 100 characters, or holding control or unassigned characters.
    """
    trimmed = name.strip()
    if not trimmed:
        raise InvalidStudentName("expected a student name, found an empty one")
    if len(trimmed) > MAX_NAME_CHARS:
        raise InvalidStudentName(f"expected at most {MAX_NAME_CHARS} characters, found {len(trimmed)}")
    bad = [c for c in trimmed if unicodedata.category(c) in {"Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"}]
    if bad:
        raise InvalidStudentName(
            f"a student name must be printable text; found the character U+{ord(bad[0]):04X}"
        )
    return trimmed


def create_student(session: Session, name: str) -> tuple[Student, str]:
    """Create a student and their token.

    Args:
        session: A database session (committed here).
        name: The requested name.

    Returns:
        The student and the token in clear (never stored; only its SHA-256 is).

    Raises:
        InvalidStudentName: See :func:`normalise_name`.
        StudentExists: The name is taken.
    """
    clean = normalise_name(name)
    if session.scalars(select(Student.id).where(Student.name == clean)).first() is not None:
        raise StudentExists(f"a student named {clean!r} already exists; choose another name")
    token = new_token()
    student = Student(name=clean, token_sha256=token_digest(token))
    session.add(student)
    try:
        session.commit()
    except IntegrityError:
        session.rollback()
        raise StudentExists(f"a student named {clean!r} already exists; choose another name") from None
    return student, token


def find_student(session: Session, name: str) -> Student:
    """The student called ``name``.

    Raises:
        StudentNotFound: Nobody has that name.
    """
    try:
        clean = normalise_name(name)
    except InvalidStudentName:
        clean = None  # no stored name can match; never send such text to the database
    student = session.scalars(select(Student).where(Student.name == clean)).first() if clean else None
    if student is None:
        raise StudentNotFound(f"no student is named {name!r}; list names with GET /gradebook.csv")
    return student
