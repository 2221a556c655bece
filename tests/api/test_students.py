"""Creating students: names are validated, tokens are returned once and stored only as digests."""

from __future__ import annotations

import hashlib
import re

import pytest
from api_testing import bearer, instructor_headers
from fastapi.testclient import TestClient
from hypothesis import given, settings
from hypothesis import strategies as st
from sqlalchemy import select

from api.errors import InvalidStudentName
from api.models import Student
from api.students import name_pattern, normalise_name


def test_a_new_student_gets_a_working_token_stored_as_a_digest(client: TestClient) -> None:
    response = client.post("/students", json={"name": "  Ada Lovelace "}, headers=instructor_headers())
    assert response.status_code == 201
    body = response.json()
    assert body["name"] == "Ada Lovelace"
    assert body["token"].startswith("gg_") and len(body["token"]) > 40
    assert client.get("/submissions", headers=bearer(body["token"])).status_code == 200
    with client.app.state.context.sessions() as session:  # type: ignore[attr-defined]
        stored = session.scalars(select(Student)).one()
    assert stored.token_sha256 == hashlib.sha256(body["token"].encode()).hexdigest()


@pytest.mark.parametrize(
    ("name", "status", "detail"),
    [
        ("   ", 422, "expected a student name, found an empty one"),
        ("x" * 101, 422, "expected at most 100 characters, found 101"),
        ("bad\x00name", 422, "a student name must be printable text; found the character U+0000"),
        ("rtl\u202ename", 422, "a student name must be printable text; found the character U+202E"),
        ("ada", 409, "a student named 'ada' already exists; choose another name"),
    ],
    ids=["blank", "too-long", "nul", "bidi-override", "duplicate"],
)
def test_bad_names_are_refused_clearly(client: TestClient, name: str, status: int, detail: str) -> None:
    assert client.post("/students", json={"name": "ada"}, headers=instructor_headers()).status_code == 201
    response = client.post("/students", json={"name": name}, headers=instructor_headers())
    assert (response.status_code, response.json()) == (status, {"detail": detail})


def test_an_oversized_json_body_is_refused_before_it_is_read(client: TestClient) -> None:
    response = client.post(
        "/students",
        content=b'{"name": "' + b"x" * 400_000 + b'"}',
        headers={**instructor_headers(), "Content-Type": "application/json"},
    )
    assert response.status_code == 413
    assert response.json()["detail"].startswith("the request body is larger than the limit of")


NAME_SAMPLES = [
    "ada",
    "  Ada Lovelace ",
    "\x1cada\x1f",
    " " + "x" * 100 + "\t",
    "x" * 101,
    "a\u2028b",
    "\u2028ab",
    "a\U000e0001",
    "a\U0001f600",
    "a\U0003fffe",
    "",
]


@pytest.mark.parametrize("name", NAME_SAMPLES, ids=range(len(NAME_SAMPLES)))
def test_the_schema_pattern_accepts_exactly_the_names_the_service_accepts(name: str) -> None:
    assert _schema_accepts(name) == _service_accepts(name)


@settings(max_examples=300, derandomize=True, database=None, deadline=None)
@given(st.text(max_size=110))
def test_the_schema_pattern_agrees_with_the_service_on_any_text(name: str) -> None:
    assert _schema_accepts(name) == _service_accepts(name)


def _schema_accepts(name: str) -> bool:
    return re.fullmatch(name_pattern(), name) is not None


def _service_accepts(name: str) -> bool:
    try:
        normalise_name(name)
    except InvalidStudentName:
        return False
    return True
