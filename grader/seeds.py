"""Grading seeds: the public practice seed of `gymgrade check` and the held-out seeds instructors grade with.

Every start of every call follows from the grading seed through public, pure functions, so a file could
memorise the starts of a known seed. Students practise on `PRACTICE_SEED`; instructors grade on a seed
drawn at random (`held_out_seed`) and recorded in each report, so a regrade with it is identical.
"""

from __future__ import annotations

import secrets

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
