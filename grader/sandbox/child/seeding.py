"""The grader's randomness: every seed a call uses derives from the call's seed alone.

Pure functions (`derive_call_seed`, `reset_seeds`) let the parent recompute the seeds a call must have
used (every reset takes the next seed of the call's reset stream, whatever seed the student passed);
`CallSeeds` is the child's stateful view of the same streams.
Streams are numpy `SeedSequence` children keyed by purpose, so adding a draw to one stream never
shifts another.
"""

from __future__ import annotations

import random
from enum import IntEnum

import numpy as np

_SEED_MASK = (1 << 63) - 1
_BATCH = 256


class Stream(IntEnum):
    """Purpose keys of the per-call seed streams (values are part of the reproducibility contract)."""

    CALL = 0
    PYTHON_RANDOM = 1
    NUMPY_LEGACY = 2
    DEFAULT_RNG = 3
    SPACES = 4
    RESETS = 5
    STUDENT_SEEDS = 6  # no longer drawn from: student seeds are replaced, not mapped
    UNSEEDED_GENERATORS = 7
    KEPT_GENERATORS = 8


def derive_call_seed(session_seed: int, call_index: int) -> int:
    """The seed of the `call_index`-th call (0-based) of a session seeded with `session_seed`."""
    return _draws(np.random.SeedSequence(session_seed, spawn_key=(Stream.CALL, call_index)), 1)[0]


def reset_seeds(call_seed: int, count: int) -> list[int]:
    """The first `count` seeds given to resets without a student seed, in reset order."""
    return _draws(_stream(call_seed, Stream.RESETS), count)


def space_seed(call_seed: int, env_number: int) -> int:
    """The seed for the spaces of the `env_number`-th live environment of a call."""
    sequence = np.random.SeedSequence(call_seed, spawn_key=(Stream.SPACES, env_number))
    return _draws(sequence, 1)[0]


def kept_generator_seed(call_seed: int, generator_number: int) -> int:
    """The seed a call gives the `generator_number`-th unseeded generator made before it (e.g. at import)."""
    sequence = np.random.SeedSequence(call_seed, spawn_key=(Stream.KEPT_GENERATORS, generator_number))
    return _draws(sequence, 1)[0]


class SeedStream:
    """An endless stream of 63-bit seeds, drawn in batches (prefix-stable: batching never changes values)."""

    def __init__(self, call_seed: int, stream: Stream) -> None:
        self._generator = np.random.PCG64(_stream(call_seed, stream))
        self._buffer: list[int] = []
        self._position = 0

    def next(self) -> int:
        """Return the next seed of the stream."""
        if self._position == len(self._buffer):
            self._buffer = _raw_seeds(self._generator, _BATCH)
            self._position = 0
        seed = self._buffer[self._position]
        self._position += 1
        return seed


class CallSeeds:
    """The seeds of one call: seeds `random` and numpy's legacy RNG, then hands out stream seeds."""

    def __init__(self, call_seed: int) -> None:
        self.call_seed = call_seed
        random.seed(_draws(_stream(call_seed, Stream.PYTHON_RANDOM), 1)[0])
        np.random.seed(_stream(call_seed, Stream.NUMPY_LEGACY).generate_state(4))
        self._resets = SeedStream(call_seed, Stream.RESETS)
        self._default_rngs = SeedStream(call_seed, Stream.DEFAULT_RNG)
        self._unseeded = SeedStream(call_seed, Stream.UNSEEDED_GENERATORS)

    def next_reset_seed(self) -> int:
        """The seed for the next reset (the student's own seed, if any, is replaced by it)."""
        return self._resets.next()

    def space_seed(self, env_number: int) -> int:
        """The seed for the spaces of the `env_number`-th live environment."""
        return space_seed(self.call_seed, env_number)

    def next_default_rng_seed(self) -> int:
        """The seed for the next `numpy.random.default_rng()` made without a seed."""
        return self._default_rngs.next()

    def next_unseeded_generator_seed(self) -> int:
        """The seed for the next generator gymnasium makes without a seed (e.g. a new space)."""
        return self._unseeded.next()


def _stream(call_seed: int, stream: Stream) -> np.random.SeedSequence:
    return np.random.SeedSequence(call_seed, spawn_key=(int(stream),))


def _draws(sequence: np.random.SeedSequence, count: int) -> list[int]:
    return _raw_seeds(np.random.PCG64(sequence), count)


def _raw_seeds(generator: np.random.PCG64, count: int) -> list[int]:
    return [int(value) & _SEED_MASK for value in generator.random_raw(count)]
