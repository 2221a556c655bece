"""The draws of a `numpy.random.Generator` seeded by gymnasium, without building the Generator.

`gymnasium.utils.seeding.np_random(seed)` is `Generator(PCG64(SeedSequence(seed)))`; an env's seeded
reset builds one, and `Generator.choice` converts its argument to an array at every draw. The
batched replayers only need a few draws per episode, so `SeededDraws` reproduces them from the same
`PCG64` stream: 64-bit outputs for doubles, their 32-bit halves (low first, the high half kept for the
next 32-bit draw, as numpy's PCG64 does) for bounded integers.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TypeVar

import numpy as np

RAW_DRAWS = 8
"""64-bit outputs drawn per seed up front; an episode that needs more draws more as it goes."""
_LOW_32 = 0xFFFFFFFF
_DOUBLE_UNIT = 1.0 / 9007199254740992.0
_T = TypeVar("_T")


class SeededDraws:
    """The draws `gymnasium.utils.seeding.np_random(seed)[0]` makes, for the methods gymnasium's envs use.

    Provides `choice(sequence)` (no size, replacement or weights: Blackjack's cards), `random()`
    (Taxi's initial state) and `bounded(count)` (`Generator.integers(0, count)`).
    """

    def __init__(self, seed: int) -> None:
        self._bit_generator = np.random.PCG64(np.random.SeedSequence(seed))
        self._raws: list[int] = []
        self._position = 0
        self._kept_half: int | None = None

    def choice(self, sequence: Sequence[_T]) -> _T:
        """The element `Generator.choice(sequence)` returns (as the sequence holds it)."""
        return sequence[self.bounded(len(sequence))]

    def random(self) -> float:
        """`Generator.random()`: the top 53 bits of the next 64-bit output."""
        return (self._next_uint64() >> 11) * _DOUBLE_UNIT

    def bounded(self, count: int) -> int:
        """`Generator.integers(0, count)` for 1 <= count <= 2**32: Lemire's method, as numpy does it."""
        if count == 1:
            return 0
        product = self._next_uint32() * count
        leftover = product & _LOW_32
        if leftover < count:
            threshold = (_LOW_32 - (count - 1)) % count
            while leftover < threshold:
                product = self._next_uint32() * count
                leftover = product & _LOW_32
        return product >> 32

    def _next_uint64(self) -> int:
        if self._position == len(self._raws):
            self._raws = self._bit_generator.random_raw(RAW_DRAWS).tolist()
            self._position = 0
        value: int = self._raws[self._position]
        self._position += 1
        return value

    def _next_uint32(self) -> int:
        if self._kept_half is not None:
            half, self._kept_half = self._kept_half, None
            return half
        raw = self._next_uint64()
        self._kept_half = raw >> 32
        return raw & _LOW_32
