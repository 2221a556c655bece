"""Winnowing (Schleimer, Wilkerson and Aiken, SIGMOD 2003) over the k-grams of normalised tokens.

Written here rather than taken from ``copydetect``: copydetect fingerprints its own lexer's tokens of
whole files and offers no hook for our AST tokens, per-function units or stable hashes (a reference cache
must give the same hashes in every process, which Python's ``hash`` of ``str`` does not).

Every k-gram of a unit gets a 64-bit hash; in each window of ``w`` consecutive hashes the minimum is
kept (the rightmost on ties). Any run of ``w + k - 1`` equal tokens therefore shares at least one
fingerprint (the guarantee threshold), and no match shorter than ``k`` tokens is ever reported.
"""

from __future__ import annotations

import hashlib
from collections import deque
from dataclasses import dataclass
from functools import lru_cache

from grader.classroom.similarity.normalise import Unit

K = 16
"""Tokens per k-gram: about a line and a half of code (a statement is 5-15 AST tokens)."""
WINDOW = 8
"""Window of the winnowing: a shared run of K + WINDOW - 1 = 23 tokens always yields a shared fingerprint."""
_MODULUS = (1 << 61) - 1
_BASE = 1_000_003


@dataclass(frozen=True)
class Fingerprint:
    """One selected k-gram hash and where its k-gram lies.

    Attributes:
        hash: The k-gram's hash (stable across processes and runs).
        unit: Index of the unit (function) it comes from.
        first_line: First source line of the k-gram.
        last_line: Last source line of the k-gram.
    """

    hash: int
    unit: int
    first_line: int
    last_line: int


@lru_cache(maxsize=65_536)
def _token_value(token: str) -> int:
    return int.from_bytes(hashlib.blake2b(token.encode(), digest_size=8).digest(), "big") % _MODULUS


def kgram_hashes(tokens: tuple[str, ...], k: int = K) -> list[int]:
    """The rolling (Karp-Rabin) hash of every k-gram of ``tokens``; empty when there are fewer than k."""
    if len(tokens) < k:
        return []
    values = [_token_value(token) for token in tokens]
    top = pow(_BASE, k - 1, _MODULUS)
    current = 0
    for value in values[:k]:
        current = (current * _BASE + value) % _MODULUS
    hashes = [current]
    for index in range(k, len(values)):
        current = ((current - values[index - k] * top) * _BASE + values[index]) % _MODULUS
        hashes.append(current)
    return hashes


def winnow(hashes: list[int], window: int = WINDOW) -> list[int]:
    """Positions of the hashes winnowing selects (each window's rightmost minimum), in order, each once."""
    if not hashes:
        return []
    if len(hashes) <= window:
        smallest = min(hashes)
        return [max(index for index, value in enumerate(hashes) if value == smallest)]
    selected: list[int] = []
    candidates: deque[int] = deque()  # positions whose hashes increase strictly from left to right
    for index, value in enumerate(hashes):
        while candidates and hashes[candidates[-1]] >= value:
            candidates.pop()
        candidates.append(index)
        if candidates[0] <= index - window:
            candidates.popleft()
        if index >= window - 1 and (not selected or selected[-1] != candidates[0]):
            selected.append(candidates[0])
    return selected


def fingerprints(units: list[Unit], k: int = K, window: int = WINDOW) -> list[Fingerprint]:
    """The winnowed fingerprints of every unit, with the lines each covers."""
    found: list[Fingerprint] = []
    for number, unit in enumerate(units):
        hashes = kgram_hashes(unit.tokens, k)
        for position in winnow(hashes, window):
            lines = unit.lines[position : position + k]
            found.append(Fingerprint(hashes[position], number, min(lines), max(lines)))
    return found
