"""The tool's signing keys at rest: encrypted with GYMGRADE_KEY_ENCRYPTION_KEY, refused unencrypted outside
development, plaintext ones from before encrypted at start-up, the encryption key itself rotated, and
retired keys deleted after their grace."""

from __future__ import annotations

from collections.abc import Iterator
from datetime import timedelta

import pytest
from api_testing import SettingsFactory, instructor_headers
from cryptography.fernet import Fernet
from fastapi.testclient import TestClient
from joserfc import jwt
from sqlalchemy import Engine, select
from sqlalchemy.orm import Session, sessionmaker

from api.database import make_engine, make_session_factory, migrate
from api.errors import LtiKeysUnprotected
from api.lti.keys import protect_keys, public_jwks, published_keys, rotate, sign, signing_key
from api.main import create_app
from api.models import LtiKey, utcnow

pytestmark = pytest.mark.slow  # each test makes RSA keys (a few tenths of a second each)

GRACE = 3600.0
NEW, OLD = Fernet.generate_key().decode(), Fernet.generate_key().decode()


@pytest.fixture
def engine(make_settings: SettingsFactory) -> Iterator[Engine]:
    made = make_engine(make_settings())
    migrate(made)
    yield made
    made.dispose()


def sessions_with(
    engine: Engine, make_settings: SettingsFactory, **settings: object
) -> sessionmaker[Session]:
    """A session factory protected as the settings say (what the service does at start-up)."""
    sessions = make_session_factory(engine)
    protect_keys(sessions, make_settings(**settings))
    return sessions


def stored(engine: Engine) -> list[str]:
    with make_session_factory(engine)() as session:
        return list(session.scalars(select(LtiKey.private_pem).order_by(LtiKey.id)))


def test_keys_are_stored_encrypted_and_sign(engine: Engine, make_settings: SettingsFactory) -> None:
    sessions = sessions_with(engine, make_settings, key_encryption_key=NEW)
    with sessions() as session:
        token = sign(session, {"sub": "x"})
        assert jwt.decode(token, published_keys(session, GRACE)).claims == {"sub": "x"}
    (row,) = stored(engine)
    assert row.startswith("fernet:") and "PRIVATE KEY" not in row


def test_outside_development_no_key_is_made_or_read_unencrypted(
    engine: Engine, make_settings: SettingsFactory
) -> None:
    with sessions_with(engine, make_settings)() as session, pytest.raises(LtiKeysUnprotected) as refused:
        signing_key(session)
    assert "the LTI signing key would be stored unencrypted: set GYMGRADE_KEY_ENCRYPTION_KEY" in str(
        refused.value
    )
    assert stored(engine) == []
    with sessions_with(engine, make_settings, development=True)() as session:
        signing_key(session)
    assert stored(engine)[0].startswith("-----BEGIN PRIVATE KEY-----"), "development keeps plaintext"


def test_plaintext_keys_from_before_are_encrypted_at_start_and_keep_their_kid(
    engine: Engine, make_settings: SettingsFactory
) -> None:
    with sessions_with(engine, make_settings, development=True)() as session:
        before = signing_key(session)
    with sessions_with(engine, make_settings, key_encryption_key=NEW)() as session:
        after = signing_key(session)
    assert (after.kid, after.as_dict(private=False)) == (before.kid, before.as_dict(private=False))
    assert stored(engine)[0].startswith("fernet:")


def test_the_encryption_key_is_rotated_by_giving_new_then_old(
    engine: Engine, make_settings: SettingsFactory
) -> None:
    with sessions_with(engine, make_settings, key_encryption_key=OLD)() as session:
        kid = signing_key(session).kid
    with pytest.raises(LtiKeysUnprotected, match="is not the key the LTI signing keys were encrypted with"):
        sessions_with(engine, make_settings, key_encryption_key=NEW)
    sessions_with(engine, make_settings, key_encryption_key=f"{NEW},{OLD}")
    with sessions_with(engine, make_settings, key_encryption_key=NEW)() as session:
        assert signing_key(session).kid == kid
    unkeyed = sessions_with(engine, make_settings, development=True)
    with (
        unkeyed() as session,
        pytest.raises(LtiKeysUnprotected, match="encrypted and GYMGRADE_KEY_ENCRYPTION_KEY is not set"),
    ):
        signing_key(session)


def test_retired_keys_are_deleted_after_their_grace(engine: Engine, make_settings: SettingsFactory) -> None:
    sessions = sessions_with(engine, make_settings, key_encryption_key=NEW)
    with sessions() as session:
        first = signing_key(session).kid
        second = rotate(session, GRACE)
        assert {key["kid"] for key in public_jwks(session, GRACE)["keys"]} == {first, second}
        retired = session.scalars(select(LtiKey).where(LtiKey.kid == first)).one()
        retired.retired_at = utcnow() - timedelta(seconds=GRACE + 1)
        session.commit()
        assert {key["kid"] for key in public_jwks(session, GRACE)["keys"]} == {second}
        assert list(session.scalars(select(LtiKey.kid))) == [second], "a retired key outlived its grace"


def test_the_service_refuses_lti_without_the_key_outside_development(make_settings: SettingsFactory) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        refused = client.get("/lti/jwks")
        assert refused.status_code == 500
        assert "set GYMGRADE_KEY_ENCRYPTION_KEY" in refused.json()["detail"]
        assert client.get("/healthz").status_code == 200, "the rest of the service runs without it"
        assert client.get("/gradebook.csv", headers=instructor_headers()).status_code == 200
