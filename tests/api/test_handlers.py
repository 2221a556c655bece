"""Every error is one ErrorBody (a page on the web UI) with its documented status and headers."""

from __future__ import annotations

from typing import Any

import pytest
from api_testing import SettingsFactory, add_student, bearer, instructor_headers
from fastapi.testclient import TestClient

from api.main import create_app
from api.routes import health

MALFORMED_MULTIPART = b"--b\r\n-208660--b--\r\n"


@pytest.mark.parametrize(
    ("method", "path", "options", "status", "detail", "headers"),
    [
        (
            "post",
            "/students",
            {},
            422,
            "the request does not match this operation's schema: body: Field required",
            {},
        ),
        (
            "post",
            "/students",
            {"content": b'{"name":', "headers": {"Content-Type": "application/json"}},
            400,
            "the request body is not valid JSON (Expecting value at character 8); "
            "send the JSON object this operation documents",
            {},
        ),
        (
            "get",
            "/submissions/abc",
            {},
            422,
            "the request does not match this operation's schema: path.submission_id: Input should be a "
            "valid integer, unable to parse string as an integer, found 'abc'",
            {},
        ),
        (
            "options",
            "/submissions",
            {},
            405,
            "OPTIONS is not supported at /submissions; use GET, POST",
            {"Allow": "GET, POST"},
        ),
        (
            "delete",
            "/students",
            {},
            405,
            "DELETE is not supported at /students; use GET, POST",
            {"Allow": "GET, POST"},
        ),
        ("get", "/nothing", {}, 404, "nothing is at /nothing; the API's operations are listed at /docs", {}),
        (
            "get",
            "/gradebook.csv",
            {"headers": {}},
            401,
            "no token sent; expected `Authorization: Bearer <your token>`",
            {"WWW-Authenticate": "Bearer"},
        ),
    ],
    ids=["missing-body", "broken-json", "id-not-a-number", "options", "delete", "unknown-path", "no-token"],
)
def test_errors_are_one_model_with_their_status_and_headers(
    client: TestClient,
    method: str,
    path: str,
    options: dict[str, Any],
    status: int,
    detail: str,
    headers: dict[str, str],
) -> None:
    response = client.request(method, path, **{"headers": instructor_headers(), **options})
    assert (response.status_code, response.json()["detail"]) == (status, detail)
    assert set(response.json()) <= {"detail", "problems"}
    assert {name: response.headers.get(name) for name in headers} == headers


def test_validation_errors_list_each_problem_for_programs(client: TestClient) -> None:
    response = client.post("/students", json={"name": 7}, headers=instructor_headers())
    assert response.status_code == 422
    assert response.json()["problems"] == [
        {
            "location": ["body", "name"],
            "message": "Input should be a valid string, found 7",
            "type": "string_type",
        }
    ]


def test_a_malformed_multipart_upload_is_a_documented_400(client: TestClient) -> None:
    token = add_student(client, "ada")
    response = client.post(
        "/submissions",
        content=MALFORMED_MULTIPART,
        headers={**bearer(token), "Content-Type": "multipart/form-data; boundary=b"},
    )
    assert response.status_code == 400
    assert response.json()["detail"].startswith("the request body could not be parsed (")
    documented = client.get("/openapi.json").json()["paths"]["/submissions"]["post"]["responses"]
    assert "400" in documented


def test_an_accepted_upload_says_where_its_result_is(client: TestClient) -> None:
    token = add_student(client, "ada")
    response = client.post("/submissions", files={"file": ("opengym.py", b"x = 1\n")}, headers=bearer(token))
    assert response.status_code == 202
    assert response.headers["Location"] == f"/submissions/{response.json()['id']}"
    assert client.get(response.headers["Location"], headers=bearer(token)).json()["status"] == "queued"


def test_a_crash_is_an_error_body_too(
    make_settings: SettingsFactory, monkeypatch: pytest.MonkeyPatch
) -> None:
    def broken(_session: object) -> dict[str, int]:
        raise RuntimeError("the database went away")

    monkeypatch.setattr(health, "count_by_status", broken)
    with TestClient(create_app(make_settings(), run_workers=False), raise_server_exceptions=False) as client:
        response = client.get("/healthz")
    assert response.status_code == 500
    assert response.json() == {
        "detail": "the service failed on this request and logged why; try again, and tell the instructor "
        "if it keeps failing"
    }


@pytest.mark.parametrize(
    ("method", "path", "status"),
    [("post", "/ui/submissions", 401), ("get", "/ui/submissions", 405), ("get", "/ui/nothing", 404)],
    ids=["signed-out-upload", "wrong-method", "unknown-page"],
)
def test_the_web_ui_gets_its_error_page(client: TestClient, method: str, path: str, status: int) -> None:
    response = client.request(
        method, path, files={"file": ("a.py", b"x = 1\n")} if method == "post" else None
    )
    assert response.status_code == status
    assert response.headers["Content-Type"].startswith("text/html")
    assert "Something is not right" in response.text


def test_every_error_response_in_the_schema_is_an_error_body(client: TestClient) -> None:
    schema = client.get("/openapi.json").json()
    assert "HTTPValidationError" not in schema["components"]["schemas"]
    for path, operations in schema["paths"].items():
        for method, operation in operations.items():
            for status, response in operation["responses"].items():
                if not status.startswith("2"):
                    body = response["content"]["application/json"]["schema"]
                    assert body == {"$ref": "#/components/schemas/ErrorBody"}, (method, path, status)


def test_the_upload_links_to_its_result(client: TestClient) -> None:
    schema = client.get("/openapi.json").json()
    accepted = schema["paths"]["/submissions"]["post"]["responses"]["202"]
    link = accepted["links"]["GetSubmission"]
    target = schema["paths"]["/submissions/{submission_id}"]["get"]["operationId"]
    assert (link["operationId"], link["parameters"]) == (target, {"submission_id": "$response.body#/id"})
    assert accepted["headers"]["Location"]["required"] is True
