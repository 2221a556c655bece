"""The draws of a `numpy.random.Generator` seeded by gymnasium, without building the Generator.

`gymnasium.utils.seeding.np_random(seed)` is `Generator(PCG64(SeedSequence(seed)))`; an env's seeded
reset builds one (about 25 us, most of it numpy's per-object set-up), and `Generator.choice` converts its
argument to an array at every draw. The batched replayers need a few draws for each of thousands of seeds,
so `seeded_draws` reproduces them from the same `PCG64` streams: `SeedSequence`'s hash of every seed at
once over numpy arrays, then each stream's 128-bit state on Python ints (numpy's `pcg64.c`: XSL-RR output
after each step), 64-bit outputs for doubles, their 32-bit halves (low first, the high half kept for the
next 32-bit draw, as numpy's PCG64 does) for bounded integers. Written by hand: numpy exposes no way to
seed many generators at once. `tests/grader/sandbox/test_replay.py` checks the draws against numpy's own.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TypeVar

import numpy as np

_LOW_32 = 0xFFFFFFFF
_LOW_64 = 2**64 - 1
_LOW_128 = 2**128 - 1
_DOUBLE_UNIT = 1.0 / 9007199254740992.0
_PCG_MULTIPLIER = 0x2360ED051FC65DA44385DF649FCCF645
# numpy/random/bit_generator.pyx: SeedSequence's hash constants, pool of 4 words, 4 64-bit words of state.
_INIT_A, _MULT_A = np.uint32(0x43B0D7E5), np.uint32(0x931E8875)
_INIT_B, _MULT_B = np.uint32(0x8B51F9DD), np.uint32(0x58F38DED)
_MIX_MULT_L, _MIX_MULT_R = np.uint32(0xCA01F9DD), np.uint32(0x4973F715)
_XSHIFT = np.uint32(16)
_POOL_SIZE = 4
_STATE_WORDS = 8
MAX_SEED = 2**128
"""Seeds `seeded_draws` takes (up to 4 words of entropy: the pool's size, a single mixing pass)."""
_T = TypeVar("_T")


class SeededDraws:
    """The draws `gymnasium.utils.seeding.np_random(seed)[0]` makes, for the methods gymnasium's envs use.

    Provides `choice(sequence)` (no size, replacement or weights: Blackjack's cards), `random()`
    (Taxi's initial state) and `bounded(count)` (`Generator.integers(0, count)`). Made by `seeded_draws`.
    """

    __slots__ = ("_increment", "_kept_half", "_state")

    def __init__(self, state: int, increment: int) -> None:
        self._state = state
        self._increment = increment
        self._kept_half: int | None = None

    def choice(self, sequence: Sequence[_T]) -> _T:
        """The element `Generator.choice(sequence)` returns (as the sequence holds it).

        `bounded(len(sequence))` written out, its common path in one call: Blackjack's replay draws a
        few hundred thousand cards, and the calls of `bounded`, `_next_uint32` and `_next_uint64` cost
        more than their arithmetic.
        """
        count = len(sequence)
        if count == 1:
            return sequence[0]
        half = self._kept_half
        if half is not None:
            self._kept_half = None
        else:
            state = self._state = (self._state * _PCG_MULTIPLIER + self._increment) & _LOW_128
            mixed = ((state >> 64) ^ state) & _LOW_64
            rotation = state >> 122
            raw = ((mixed >> rotation) | (mixed << (64 - rotation))) & _LOW_64
            self._kept_half, half = raw >> 32, raw & _LOW_32
        product = half * count
        if product & _LOW_32 < count:  # Lemire's rejection, rare: `bounded` goes on from this draw
            return sequence[self._rejected(product, count)]
        return sequence[product >> 32]

    def random(self) -> float:
        """`Generator.random()`: the top 53 bits of the next 64-bit output."""
        return (self._next_uint64() >> 11) * _DOUBLE_UNIT

    def bounded(self, count: int) -> int:
        """`Generator.integers(0, count)` for 1 <= count <= 2**32: Lemire's method, as numpy does it."""
        if count == 1:
            return 0
        product = self._next_uint32() * count
        if product & _LOW_32 < count:
            return self._rejected(product, count)
        return product >> 32

    def _rejected(self, product: int, count: int) -> int:
        """Lemire's method after a first draw whose low half fell below `count`: redraw while it is below
        the threshold (numpy's `buffered_bounded_lemire_uint32`)."""
        threshold = (_LOW_32 - (count - 1)) % count
        while product & _LOW_32 < threshold:
            product = self._next_uint32() * count
        return product >> 32

    def _next_uint64(self) -> int:
        state = self._state = (self._state * _PCG_MULTIPLIER + self._increment) & _LOW_128
        mixed = ((state >> 64) ^ state) & _LOW_64
        rotation = state >> 122
        return ((mixed >> rotation) | (mixed << (64 - rotation))) & _LOW_64

    def _next_uint32(self) -> int:
        if self._kept_half is not None:
            half, self._kept_half = self._kept_half, None
            return half
        raw = self._next_uint64()
        self._kept_half = raw >> 32
        return raw & _LOW_32


def seeded_draws(seeds: Sequence[int]) -> list[SeededDraws]:
    """The draws of `np_random(seed)` for each seed (0 <= seed < `MAX_SEED`), in order.

    Raises:
        ValueError: a seed outside [0, MAX_SEED).
    """
    if any(not 0 <= seed < MAX_SEED for seed in seeds):
        raise ValueError(f"seeded_draws takes seeds in [0, 2**128), found {min(seeds)} to {max(seeds)}")
    words = _state_words(seeds)
    # generate_state(4, uint64) pairs the 32-bit words, low first; PCG64 takes (high, low) 64-bit halves.
    halves = words[:, 0::2].astype(np.uint64) | (words[:, 1::2].astype(np.uint64) << np.uint64(32))
    draws = []
    for high, low, increment_high, increment_low in halves.tolist():
        initial = high << 64 | low
        increment = ((increment_high << 64 | increment_low) << 1 | 1) & _LOW_128
        # pcg_setseq_128_srandom_r: step from 0 (state = increment), add the initial state, step again.
        state = ((increment + initial) * _PCG_MULTIPLIER + increment) & _LOW_128
        draws.append(SeededDraws(state, increment))
    return draws


def _state_words(seeds: Sequence[int]) -> np.ndarray:
    """`SeedSequence(seed).generate_state(8, uint32)` for every seed: shape (seeds, 8), uint32."""
    count = len(seeds)
    # A seed is its 32-bit words, low first, at least one; the pool hashes missing words as 0 alike.
    entropy = np.zeros((count, _POOL_SIZE), dtype=np.uint32)
    if max(seeds, default=0) <= _LOW_64:
        low_64 = np.array(seeds, dtype=np.uint64)
        entropy[:, 0] = low_64 & np.uint64(_LOW_32)
        entropy[:, 1] = low_64 >> np.uint64(32)
    else:
        entropy[:] = [[(seed >> (32 * word)) & _LOW_32 for word in range(_POOL_SIZE)] for seed in seeds]
    pool = np.empty((count, _POOL_SIZE), dtype=np.uint32)
    hash_const = _INIT_A
    with np.errstate(over="ignore"):
        for word in range(_POOL_SIZE):
            pool[:, word], hash_const = _hashmix(entropy[:, word], hash_const)
        for source in range(_POOL_SIZE):
            for target in range(_POOL_SIZE):
                if source != target:
                    hashed, hash_const = _hashmix(pool[:, source], hash_const)
                    mixed: np.ndarray = _MIX_MULT_L * pool[:, target] - _MIX_MULT_R * hashed
                    pool[:, target] = mixed ^ (mixed >> _XSHIFT)
        state = np.empty((count, _STATE_WORDS), dtype=np.uint32)
        hash_const = _INIT_B
        for word in range(_STATE_WORDS):
            value = pool[:, word % _POOL_SIZE] ^ hash_const
            hash_const = hash_const * _MULT_B
            value = value * hash_const
            state[:, word] = value ^ (value >> _XSHIFT)
    return state


def _hashmix(value: np.ndarray, hash_const: np.uint32) -> tuple[np.ndarray, np.uint32]:
    value = value ^ hash_const
    hash_const = hash_const * _MULT_A
    value = value * hash_const
    return value ^ (value >> _XSHIFT), hash_const
