"""Schemathesis against the OpenAPI schema: no generated request, whoever sends it, gets a 5xx."""

from __future__ import annotations

from typing import Any

import pytest
import schemathesis
from api_testing import FAKE_GRADER, INSTRUCTOR_TOKEN, bearer, instructor_headers
from hypothesis import HealthCheck, settings
from pydantic import SecretStr
from schemathesis.checks import not_a_server_error

from api.context import ServiceContext
from api.courses import DEFAULT_COURSE_ID
from api.main import create_app
from api.settings import Settings
from api.students import create_student

pytestmark = pytest.mark.slow  # schemathesis generates requests against the app on both databases

EXAMPLES_PER_OPERATION = 30


@pytest.fixture(scope="module", params=["sqlite", "postgresql"])
def service_settings(tmp_path_factory: pytest.TempPathFactory, request: pytest.FixtureRequest) -> Settings:
    database_url = None
    if request.param == "postgresql":
        database_url = request.getfixturevalue("postgres_server").new_database()
    return Settings(
        database_url=database_url,
        data_dir=tmp_path_factory.mktemp("openapi"),
        instructor_token=SecretStr(INSTRUCTOR_TOKEN),
        grader=FAKE_GRADER,
        workers=0,
        max_upload_bytes=4096,
    )


@pytest.fixture(scope="module")
def student_token(service_settings: Settings) -> str:
    context = ServiceContext.open(service_settings, pool_size=0)
    with context.sessions() as session:
        _, token = create_student(session, DEFAULT_COURSE_ID, "schemathesis")
    context.close()
    return token


@pytest.fixture(scope="module")
def api_schema(service_settings: Settings) -> schemathesis.BaseSchema:
    return schemathesis.openapi.from_asgi("/openapi.json", create_app(service_settings, run_workers=False))


schema = schemathesis.pytest.from_fixture("api_schema")


@schema.parametrize()
@settings(
    max_examples=EXAMPLES_PER_OPERATION,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=list(HealthCheck),
)
def test_no_request_gets_a_server_error(case: schemathesis.Case[Any], student_token: str) -> None:
    for headers in (instructor_headers(), bearer(student_token), {}):
        case.call_and_validate(headers=headers, checks=[not_a_server_error])
