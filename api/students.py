"""Creating students (a course's enrolments, each with its own token) and finding them in a course: by their
id (what overrides and extensions are keyed by) or by their name (unique in the course)."""

from __future__ import annotations

import sys
import unicodedata
from functools import cache

from sqlalchemy import select
from sqlalchemy.exc import IntegrityError
from sqlalchemy.orm import Session

from api.errors import InvalidStudentName, StudentExists, StudentNotFound
from api.models import Student
from api.security import new_token, token_digest

MAX_NAME_CHARS = 100
MAX_ID = 2**31 - 1
"""The largest id every database's integer column holds: a larger one in a path is nobody's."""
# Control, format (bidi overrides, zero-width), surrogate, private-use and line/paragraph separator
# characters. Unassigned code points are allowed: a newer Unicode than the server's may assign them (new
# emoji), and no JSON Schema pattern could follow the server's Unicode version.
FORBIDDEN_NAME_CATEGORIES = frozenset({"Cc", "Cf", "Cs", "Co", "Zl", "Zp"})


def normalise_name(name: str) -> str:
    """Validate a student name and return it trimmed.

    Raises:
        InvalidStudentName: Empty, longer than 100 characters, or holding control or format characters.
    """
    trimmed = name.strip()
    if not trimmed:
        raise InvalidStudentName("expected a student name, found an empty one")
    if len(trimmed) > MAX_NAME_CHARS:
        raise InvalidStudentName(f"expected at most {MAX_NAME_CHARS} characters, found {len(trimmed)}")
    bad = [c for c in trimmed if unicodedata.category(c) in FORBIDDEN_NAME_CATEGORIES]
    if bad:
        raise InvalidStudentName(
            f"a student name must be printable text; found the character U+{ord(bad[0]):04X}"
        )
    return trimmed


def printable(text: str, fallback: str) -> str:
    """``text`` to show (a course's title, a staff member's name): without the characters a name may not hold
    and the whitespace around it, at most ``MAX_NAME_CHARS`` characters; ``fallback`` when nothing is left."""
    kept = "".join(c for c in text if unicodedata.category(c) not in FORBIDDEN_NAME_CATEGORIES).strip()
    return kept[:MAX_NAME_CHARS].strip() or fallback


def _spelled(code_point: int) -> str:
    # \uXXXX reads the same in ECMA-262 and Python patterns; beyond the BMP only the character itself does.
    return f"\\u{code_point:04x}" if code_point <= 0xFFFF else chr(code_point)


def _character_class(code_points: list[int], *, negated: bool) -> str:
    """A regex character class of ``code_points`` (ascending), merged into ranges."""
    ranges: list[list[int]] = []
    for code_point in code_points:
        if ranges and ranges[-1][1] == code_point - 1:
            ranges[-1][1] = code_point
        else:
            ranges.append([code_point, code_point])
    parts = [_spelled(low) if low == high else f"{_spelled(low)}-{_spelled(high)}" for low, high in ranges]
    return "[" + ("^" if negated else "") + "".join(parts) + "]"


@cache
def name_pattern() -> str:
    """The names :func:`normalise_name` accepts, as a JSON Schema ``pattern`` (built from the same rules).

    Any whitespace around a name is trimmed; what remains is 1 to ``MAX_NAME_CHARS`` characters, none of
    them in ``FORBIDDEN_NAME_CATEGORIES``.
    """
    category = unicodedata.category
    # Surrogates are left out: no UTF-8 text holds them, and regex engines refuse them in a class.
    every = [point for point in range(sys.maxunicode + 1) if not 0xD800 <= point <= 0xDFFF]
    forbidden = [point for point in every if category(chr(point)) in FORBIDDEN_NAME_CATEGORIES]
    space = [point for point in every if chr(point).isspace()]
    around = _character_class(space, negated=False)
    edge = _character_class(sorted(set(forbidden) | set(space)), negated=True)
    inner = _character_class(forbidden, negated=True)
    return f"^{around}*{edge}(?:{inner}{{0,{MAX_NAME_CHARS - 2}}}{edge})?{around}*$"


def create_student(session: Session, course_id: int, name: str) -> tuple[Student, str]:
    """Enrol a student in a course and make their token.

    Args:
        session: A database session (committed here).
        course_id: The course.
        name: The requested name (unique in the course).

    Returns:
        The student and the token in clear (never stored; only its SHA-256 is).

    Raises:
        InvalidStudentName: See :func:`normalise_name`.
        StudentExists: The name is taken in the course.
    """
    clean = normalise_name(name)
    if name_taken(session, course_id, clean):
        raise StudentExists(f"a student named {clean!r} already exists; choose another name")
    token = new_token()
    student = Student(course_id=course_id, name=clean, token_sha256=token_digest(token))
    session.add(student)
    try:
        session.commit()
    except IntegrityError:
        session.rollback()
        raise StudentExists(f"a student named {clean!r} already exists; choose another name") from None
    return student, token


def name_taken(session: Session, course_id: int, name: str) -> bool:
    """Whether an enrolment of the course is called ``name`` (normalised)."""
    query = select(Student.id).where(Student.course_id == course_id, Student.name == name)
    return session.scalars(query).first() is not None


def find_student(session: Session, course_id: int, name: str) -> Student:
    """The course's student called ``name``.

    Raises:
        StudentNotFound: Nobody of the course has that name.
    """
    try:
        clean = normalise_name(name)
    except InvalidStudentName:
        clean = None  # no stored name can match; never send such text to the database
    query = select(Student).where(Student.course_id == course_id, Student.name == clean)
    student = session.scalars(query).first() if clean else None
    if student is None:
        raise StudentNotFound(f"no student is named {name!r}; list names with GET /gradebook.csv")
    return student


def find_enrolment(session: Session, course_id: int, enrolment_id: int) -> Student:
    """The course's enrolment with id ``enrolment_id``.

    Raises:
        StudentNotFound: The course has no enrolment of that id.
    """
    student = session.get(Student, enrolment_id) if 1 <= enrolment_id <= MAX_ID else None
    if student is None or student.course_id != course_id:
        raise StudentNotFound(
            f"no enrolment {enrolment_id} in this course; list the course's with GET .../students"
        )
    return student


def enrolments_of(session: Session, course_id: int) -> list[Student]:
    """The course's enrolments, by name."""
    return list(session.scalars(select(Student).where(Student.course_id == course_id).order_by(Student.name)))
