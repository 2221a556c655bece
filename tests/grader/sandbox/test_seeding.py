"""The grader's seed streams: pure, reproducible, prefix-stable, and separate per purpose."""

from __future__ import annotations

import random
from collections.abc import Iterator

import numpy as np
import pytest

from grader.sandbox.child.seeding import (
    CallSeeds,
    SeedStream,
    Stream,
    derive_call_seed,
    reset_seeds,
    space_seed,
)


def test_call_seeds_depend_on_the_session_seed_and_the_call_index_only() -> None:
    seeds = [derive_call_seed(7, index) for index in range(50)]

    assert seeds == [derive_call_seed(7, index) for index in range(50)]
    assert len(set(seeds)) == 50
    assert derive_call_seed(8, 0) != seeds[0]
    assert all(0 <= seed < 2**63 for seed in seeds)


@pytest.mark.parametrize("count", [1, 255, 256, 257, 1000])
def test_the_reset_stream_is_prefix_stable_across_batches(count: int) -> None:
    stream = SeedStream(11, Stream.RESETS)

    assert [stream.next() for _ in range(count)] == reset_seeds(11, 1000)[:count]


@pytest.mark.usefixtures("global_generators")
def test_streams_for_different_purposes_differ() -> None:
    seeds = CallSeeds(3)

    draws = {
        seeds.next_reset_seed(),
        seeds.next_default_rng_seed(),
        seeds.next_unseeded_generator_seed(),
        seeds.space_seed(0),
        space_seed(3, 1),
    }

    assert len(draws) == 5


@pytest.fixture
def global_generators() -> Iterator[None]:
    """Restore `random` and numpy's global generator: CallSeeds reseeds them for the whole process."""
    python_state, numpy_state = random.getstate(), np.random.get_state()
    yield
    random.setstate(python_state)
    np.random.set_state(numpy_state)


@pytest.mark.usefixtures("global_generators")
def test_call_seeds_reseed_random_and_numpys_global_generator() -> None:
    CallSeeds(5)
    first = (random.random(), np.random.rand())
    CallSeeds(5)
    again = (random.random(), np.random.rand())
    CallSeeds(6)
    other = (random.random(), np.random.rand())

    assert first == again
    assert first[0] != other[0] and first[1] != other[1]
