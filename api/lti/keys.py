"""The tool's own RSA signing keys: generated on first use, stored in the database, rotated with a grace.

The newest unretired key signs (the launch state, the client assertions of the Advantage services, deep
linking responses). A rotation retires the others without deleting them: for ``grace`` seconds they are
still published at the JWKS URL (platforms cache it) and still accepted for the tool's own state tokens,
so a launch started before the rotation completes after it. Signing and verifying go through joserfc.
"""

from __future__ import annotations

from datetime import timedelta
from typing import Any

from joserfc import jwt
from joserfc.jwk import KeySet, RSAKey
from sqlalchemy import or_, select
from sqlalchemy.orm import Session

from api.models import LtiKey, utcnow

ALGORITHM = "RS256"
KEY_BITS = 2048


def _new_key(session: Session) -> LtiKey:
    key = RSAKey.generate_key(KEY_BITS, parameters={"use": "sig", "alg": ALGORITHM}, auto_kid=True)
    row = LtiKey(kid=key.kid, private_pem=key.as_pem(private=True).decode("ascii"))
    session.add(row)
    session.flush()
    return row


def _load(row: LtiKey) -> RSAKey:
    return RSAKey.import_key(row.private_pem, {"kid": row.kid, "use": "sig", "alg": ALGORITHM})


def signing_key(session: Session) -> RSAKey:
    """The key that signs now: the newest unretired one, made (and committed) when there is none."""
    row = session.scalars(
        select(LtiKey).where(LtiKey.retired_at.is_(None)).order_by(LtiKey.id.desc())
    ).first()
    if row is None:
        row = _new_key(session)
        session.commit()
    return _load(row)


def rotate(session: Session) -> str:
    """Make a new signing key and retire the others (they stay published for the grace); return its kid."""
    now = utcnow()
    for row in session.scalars(select(LtiKey).where(LtiKey.retired_at.is_(None))):
        row.retired_at = now
    row = _new_key(session)
    session.commit()
    return row.kid


def published_keys(session: Session, grace_seconds: float) -> KeySet:
    """The keys still valid: unretired, or retired less than ``grace_seconds`` ago (private parts held)."""
    oldest = utcnow() - timedelta(seconds=grace_seconds)
    signing_key(session)
    rows = session.scalars(
        select(LtiKey).where(or_(LtiKey.retired_at.is_(None), LtiKey.retired_at > oldest)).order_by(LtiKey.id)
    )
    return KeySet([_load(row) for row in rows])


def public_jwks(session: Session, grace_seconds: float) -> dict[str, Any]:
    """The JWKS document served to platforms: the public halves of :func:`published_keys`."""
    return dict(published_keys(session, grace_seconds).as_dict(private=False))


def sign(session: Session, claims: dict[str, Any]) -> str:
    """A JWT of ``claims`` signed with the current key (its ``kid`` in the header)."""
    key = signing_key(session)
    return jwt.encode({"alg": ALGORITHM, "kid": key.kid, "typ": "JWT"}, claims, key)
