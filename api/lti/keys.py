"""The tool's own RSA signing keys: generated on first use, stored in the database, rotated with a grace.

The newest unretired key signs (the launch state, the client assertions of the Advantage services, deep
linking responses). A rotation retires the others: for ``grace`` seconds they are still published at the
JWKS URL (platforms cache it) and still accepted for the tool's own state tokens, so a launch started
before the rotation completes after it; after the grace they are deleted. Signing and verifying go
through joserfc.

Private keys are stored encrypted (Fernet, ``fernet:`` before the token) with GYMGRADE_KEY_ENCRYPTION_KEY
(several, comma-separated: the first encrypts, any decrypts, so the key itself can be rotated). The
:class:`KeyProtection` travels in the database session's ``info`` (set once by :func:`protect_keys` on the
session factory), so every caller's ``sign(session, ...)`` stays as it is. Without the setting, keys are
made and read only in development. A key stored in plaintext (before encryption existed) is still read,
and encrypted again by :func:`protect_keys` at start-up.
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import timedelta
from typing import Any

from cryptography.fernet import Fernet, InvalidToken, MultiFernet
from joserfc import jwt
from joserfc.jwk import KeySet, RSAKey
from sqlalchemy import delete, or_, select
from sqlalchemy.orm import Session, sessionmaker

from api.errors import LtiKeysUnprotected
from api.models import LtiKey, utcnow
from api.settings import Settings

ALGORITHM = "RS256"
KEY_BITS = 2048
SEALED = "fernet:"
PROTECTION = "gymgrade.lti.key_protection"
"""The key of the session's ``info`` holding its :class:`KeyProtection`."""


@dataclass(frozen=True)
class KeyProtection:
    """How private keys are stored: encrypted with the operator's keys, or (development only) not."""

    cipher: MultiFernet | None
    development: bool

    @classmethod
    def of(cls, settings: Settings) -> KeyProtection:
        """The protection the settings give."""
        secret = settings.key_encryption_key
        keys = [item.strip() for item in secret.get_secret_value().split(",")] if secret is not None else []
        cipher = MultiFernet([Fernet(key) for key in keys if key]) if keys else None
        return cls(cipher, settings.development)

    def seal(self, pem: str) -> str:
        """What the database stores of a private key."""
        if self.cipher is not None:
            return SEALED + self.cipher.encrypt(pem.encode("ascii")).decode("ascii")
        if self.development:
            return pem
        raise LtiKeysUnprotected(
            "the LTI signing key would be stored unencrypted: set GYMGRADE_KEY_ENCRYPTION_KEY (`python -c 'from cryptography.fernet import Fernet; print(Fernet.generate_key().decode())'`) and restart; "  # noqa: E501
            "only GYMGRADE_DEVELOPMENT=1 keeps keys in plaintext"
        )

    def open(self, stored: str) -> str:
        """The private key's PEM from what the database stores (sealed, or plaintext from before)."""
        if not stored.startswith(SEALED):
            return stored
        if self.cipher is None:
            raise LtiKeysUnprotected(
                "the LTI signing keys are encrypted and GYMGRADE_KEY_ENCRYPTION_KEY is not set; "
                "set it to the key they were encrypted with and restart"
            )
        try:
            return self.cipher.decrypt(stored.removeprefix(SEALED).encode("ascii")).decode("ascii")
        except InvalidToken:
            raise LtiKeysUnprotected(
                "GYMGRADE_KEY_ENCRYPTION_KEY is not the key the LTI signing keys were encrypted with; "
                "give the old key after the new one (NEW,OLD) and restart: they are encrypted again with the new"  # noqa: E501
            ) from None


def protect_keys(sessions: sessionmaker[Session], settings: Settings) -> None:
    """Give every session of ``sessions`` the settings' :class:`KeyProtection`, and encrypt again with
    the first key every stored key that is plaintext or encrypted with another (when a key is set)."""
    protection = KeyProtection.of(settings)
    sessions.configure(info={PROTECTION: protection})
    if protection.cipher is None:
        return
    with sessions() as session:
        for row in session.scalars(select(LtiKey)):
            pem = protection.open(row.private_pem)
            if not row.private_pem.startswith(SEALED):
                row.private_pem = protection.seal(pem)
            else:
                sealed = row.private_pem.removeprefix(SEALED).encode("ascii")
                row.private_pem = SEALED + protection.cipher.rotate(sealed).decode("ascii")
        session.commit()


def _protection(session: Session) -> KeyProtection:
    protection = session.info.get(PROTECTION)
    if not isinstance(protection, KeyProtection):
        raise LtiKeysUnprotected(
            "this database session was opened without the key protection (api.lti.keys.protect_keys)"
        )
    return protection


def _new_key(session: Session) -> LtiKey:
    key = RSAKey.generate_key(KEY_BITS, parameters={"use": "sig", "alg": ALGORITHM}, auto_kid=True)
    sealed = _protection(session).seal(key.as_pem(private=True).decode("ascii"))
    row = LtiKey(kid=key.kid, private_pem=sealed)
    session.add(row)
    session.flush()
    return row


def _load(session: Session, row: LtiKey) -> RSAKey:
    pem = _protection(session).open(row.private_pem)
    return RSAKey.import_key(pem, {"kid": row.kid, "use": "sig", "alg": ALGORITHM})


def signing_key(session: Session) -> RSAKey:
    """The key that signs now: the newest unretired one, made (and committed) when there is none."""
    row = session.scalars(
        select(LtiKey).where(LtiKey.retired_at.is_(None)).order_by(LtiKey.id.desc())
    ).first()
    if row is None:
        row = _new_key(session)
        session.commit()
    return _load(session, row)


def rotate(session: Session, grace_seconds: float) -> str:
    """Make a new signing key and retire the others (they stay published for the grace; those retired
    longer ago are deleted); return its kid."""
    now = utcnow()
    delete_expired(session, grace_seconds)
    for row in session.scalars(select(LtiKey).where(LtiKey.retired_at.is_(None))):
        row.retired_at = now
    row = _new_key(session)
    session.commit()
    return row.kid


def delete_expired(session: Session, grace_seconds: float) -> int:
    """Delete the keys retired more than ``grace_seconds`` ago (not committed); how many."""
    oldest = utcnow() - timedelta(seconds=grace_seconds)
    result = session.execute(
        delete(LtiKey).where(LtiKey.retired_at.is_not(None), LtiKey.retired_at <= oldest)
    )
    return int(result.rowcount or 0)  # type: ignore[attr-defined]


def published_keys(session: Session, grace_seconds: float) -> KeySet:
    """The keys still valid: unretired, or retired less than ``grace_seconds`` ago (private parts held)."""
    oldest = utcnow() - timedelta(seconds=grace_seconds)
    signing_key(session)
    rows = session.scalars(
        select(LtiKey).where(or_(LtiKey.retired_at.is_(None), LtiKey.retired_at > oldest)).order_by(LtiKey.id)
    )
    return KeySet([_load(session, row) for row in rows])


def public_jwks(session: Session, grace_seconds: float) -> dict[str, Any]:
    """The JWKS document served to platforms: the public halves of :func:`published_keys` (the keys
    past their grace are deleted first)."""
    if delete_expired(session, grace_seconds):
        session.commit()
    return dict(published_keys(session, grace_seconds).as_dict(private=False))


def sign(session: Session, claims: dict[str, Any]) -> str:
    """A JWT of ``claims`` signed with the current key (its ``kid`` in the header)."""
    key = signing_key(session)
    return jwt.encode({"alg": ALGORITHM, "kid": key.kid, "typ": "JWT"}, claims, key)
