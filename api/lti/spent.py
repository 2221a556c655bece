"""Single-use tokens of the tool's own (a registration ticket, a lab picker's form): a token's ``jti`` is
stored when it is used, and a second use is refused; rows are kept until the token would have expired."""

from __future__ import annotations

from datetime import UTC, datetime

from sqlalchemy import delete, select
from sqlalchemy.exc import IntegrityError
from sqlalchemy.orm import Session

from api.models import LtiSpentToken, utcnow


class TokenSpent(Exception):
    """Raised when a single-use token was used before."""


def spend(session: Session, purpose: str, jti: str, expires: int, *, check_only: bool = False) -> None:
    """Mark the token ``jti`` used (committed), or, with ``check_only``, only check it was not.

    Raises:
        TokenSpent: It was used before.
    """
    key = f"{purpose}:{jti}"[:100]
    if check_only:
        if session.scalars(select(LtiSpentToken.jti).where(LtiSpentToken.jti == key)).first() is not None:
            raise TokenSpent(key)
        return
    session.execute(delete(LtiSpentToken).where(LtiSpentToken.expires_at < utcnow()))
    until = datetime.fromtimestamp(expires, UTC).replace(tzinfo=None)
    session.add(LtiSpentToken(jti=key, purpose=purpose, expires_at=until))
    try:
        session.commit()
    except IntegrityError:
        session.rollback()
        raise TokenSpent(key) from None
