"""Grading seeds: the public practice seed of `gymgrade check` and the held-out seeds instructors grade with.

Every start of every call follows from the grading seed through public, pure functions, so a file could
memorise the starts of a known seed. Students practise on `PRACTICE_SEED`; instructors grade on a seed
drawn at random (`held_out_seed`) and recorded in each report, so a regrade with it is identical. Where no
database can record a fresh seed per upload (the Gradescope bundle), each upload's seed is derived from a
secret and the upload's identity (`upload_seed`): different for every upload, unpredictable without the
secret, and recomputed by whoever holds it.

In detail:

- `grader/seeds.py`: `PRACTICE_SEED = 0` (what `gymgrade check` plays on unless given `--seed`) and
  `held_out_seed(limit=2**63)`, a `secrets` draw in [1, limit): what `gymgrade grade` uses without
  `--seed` (printed, in every report and the `seed` column of `grades.csv`) and the service per submission.
- `grader/seeds.py`: `new_secret()` (256-bit hex) and `upload_seed(secret, identity, limit=2**63)`:
  HMAC-SHA256 of the identity (a sequence of strings, JSON-encoded) under the secret, in [1, limit). Pure.
"""

from __future__ import annotations

import hashlib
import hmac
import json
import secrets
from collections.abc import Sequence

PRACTICE_SEED = 0
"""The seed `gymgrade check` uses unless told otherwise: public, so never a grading seed."""

SEED_LIMIT = 2**63
"""Grading seeds are non-negative and below this (they feed numpy's SeedSequence)."""


def held_out_seed(limit: int = SEED_LIMIT) -> int:
    """A fresh, unpredictable grading seed in [1, limit), never the practice seed.

    Args:
        limit: Exclusive upper bound (e.g. 2**31 for a 32-bit database column).
    """
    return 1 + secrets.randbelow(limit - 1)


SECRET_BYTES = 32
"""Length of a seed secret (256 bits, as HMAC-SHA256 uses)."""


def new_secret() -> str:
    """A fresh seed secret, as the hex text a bundle keeps it in."""
    return secrets.token_hex(SECRET_BYTES)


def upload_seed(secret: str, identity: Sequence[str], limit: int = SEED_LIMIT) -> int:
    """The grading seed of one upload: HMAC-SHA256 of its identity under ``secret``, in [1, limit).

    Without the secret the seed of an upload cannot be told from the seeds (or starts) of any other upload,
    so what one upload's code learns about its starts says nothing about the next upload's.

    Args:
        secret: The hex secret (`new_secret`).
        identity: What names the upload, in a fixed order (e.g. Gradescope's submission id, its users and
            its time); any change gives an unrelated seed.
        limit: Exclusive upper bound.

    Raises:
        ValueError: ``secret`` is not hex text of at least `SECRET_BYTES` bytes.
    """
    try:
        key = bytes.fromhex(secret.strip())
    except ValueError:
        key = b""
    if len(key) < SECRET_BYTES:
        raise ValueError(
            f"a seed secret must be at least {SECRET_BYTES * 2} hex digits; found {len(secret.strip())} "
            "characters: use the seed_secret file of the autograder bundle unchanged"
        )
    message = json.dumps(list(identity), separators=(",", ":"), ensure_ascii=True).encode()
    digest = hmac.new(key, b"gymgrade-upload-seed:" + message, hashlib.sha256).digest()
    return 1 + int.from_bytes(digest[:8], "big") % (limit - 1)
