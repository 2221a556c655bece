"""The Open edX platform of the tests refuses what Open edX refuses, so that a scenario passing against it
means the tool's calls passed Open edX's own checks: `lti-consumer-xblock`'s consumer checks every service
call's token (signature, issuer, scope), and the line item keeps only a newer score."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import pytest
from fastapi.testclient import TestClient

pytest.importorskip("lti_consumer", reason="pip install -e '.[dev]' (lti-consumer-xblock)")

from lti_consumer.lti_1p3.key_handlers import PlatformKeyHandler
from openedx_platform import NRPS_SCOPE, SCORE_SCOPE, Block, OpenEdxPlatform, Passport

pytestmark = pytest.mark.slow  # RSA keys made and parsed for each request, as Open edX does

COURSE = "course-v1:Uni+RL+2026"
SCORE = {
    "userId": "learner-1",
    "timestamp": "2026-12-08T01:00:00.000000Z",
    "scoreGiven": 2.0,
    "scoreMaximum": 3.0,
    "activityProgress": "Completed",
    "gradingProgress": "FullyGraded",
}


@pytest.fixture
def lms() -> Iterator[tuple[OpenEdxPlatform, Block, TestClient]]:
    platform = OpenEdxPlatform()
    platform.use_tool("http://127.0.0.1:9")
    block = platform.add_block(Passport(), COURSE, "Reinforcement learning")
    with TestClient(platform.app) as client:
        yield platform, block, client


def _token(platform: OpenEdxPlatform, passport: Passport, scopes: str, **claims: Any) -> str:
    """An access token as the passport's token endpoint signs them (the consumer's key handler)."""
    token: str = PlatformKeyHandler(passport.private_key, passport.kid).encode_and_sign(
        {"sub": passport.client_id, "iss": platform.issuer, "scopes": scopes, **claims}, expiration=3600
    )
    return token


def _scores_url(block: Block) -> str:
    return f"/api/lti_consumer/v1/lti/{block.config_id}/lti-ags/1/scores"


TOKENS: dict[str, Callable[[OpenEdxPlatform, Block], dict[str, str]]] = {
    "no token": lambda platform, block: {},
    "another passport's key": lambda platform, block: {
        "Authorization": "Bearer " + _token(platform, Passport(), SCORE_SCOPE)
    },
    "another issuer": lambda platform, block: {
        "Authorization": "Bearer " + _token(platform, block.passport, SCORE_SCOPE, iss="https://evil.test")
    },
    "no score scope": lambda platform, block: {
        "Authorization": "Bearer " + _token(platform, block.passport, NRPS_SCOPE)
    },
}


@pytest.mark.parametrize("case", list(TOKENS), ids=list(TOKENS))
def test_a_score_without_a_valid_token_of_the_score_scope_is_refused(
    lms: tuple[OpenEdxPlatform, Block, TestClient], case: str
) -> None:
    platform, block, client = lms
    answer = client.post(_scores_url(block), json=SCORE, headers=TOKENS[case](platform, block))
    assert answer.status_code == 403, answer.text
    assert block.scores == {} and platform.denied


def test_the_line_item_keeps_only_a_newer_score(lms: tuple[OpenEdxPlatform, Block, TestClient]) -> None:
    platform, block, client = lms
    headers = {"Authorization": "Bearer " + _token(platform, block.passport, SCORE_SCOPE)}
    assert client.post(_scores_url(block), json=SCORE, headers=headers).status_code == 201
    same = client.post(_scores_url(block), json={**SCORE, "scoreGiven": 3.0}, headers=headers)
    older = client.post(
        _scores_url(block),
        json={**SCORE, "timestamp": "2026-12-08T00:59:59Z", "scoreGiven": 3.0},
        headers=headers,
    )
    assert (same.status_code, older.status_code) == (400, 400)
    assert [reason for _, reason in block.refused] == [
        "Score already exists for the provided timestamp",
        "Score timestamp can only be updated to a later point in time",
    ]
    newer = client.post(
        _scores_url(block),
        json={**SCORE, "timestamp": "2026-12-08T01:00:01Z", "scoreGiven": 3.0},
        headers=headers,
    )
    assert newer.status_code == 201 and block.scores["learner-1"]["scoreGiven"] == 3.0
