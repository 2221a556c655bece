"""Winnowing keeps the guarantee of Schleimer, Wilkerson and Aiken: a long shared run is always seen."""

from __future__ import annotations

import random

import pytest

from grader.classroom.similarity.winnow import WINDOW, K, kgram_hashes, winnow


def _tokens(rng: random.Random, length: int) -> tuple[str, ...]:
    return tuple(
        rng.choice(["Name", "Call", "ID", "Assign", "For", "INT", ".step", "BinOp", "Add"])
        for _ in range(length)
    )


def test_each_window_keeps_its_rightmost_minimum() -> None:
    hashes = [5, 3, 9, 3, 7, 8, 2, 6]
    assert winnow(hashes, window=4) == [3, 6]


@pytest.mark.parametrize("seed", range(20), ids=[f"seed {seed}" for seed in range(20)])
def test_a_shared_run_of_k_plus_w_minus_1_tokens_always_shares_a_fingerprint(seed: int) -> None:
    rng = random.Random(seed)
    shared = _tokens(rng, K + WINDOW - 1)
    first = _tokens(rng, rng.randrange(0, 40)) + shared + _tokens(rng, rng.randrange(0, 40))
    second = _tokens(rng, rng.randrange(0, 40)) + shared + _tokens(rng, rng.randrange(0, 40))
    first_hashes, second_hashes = kgram_hashes(first), kgram_hashes(second)
    selected_first = {first_hashes[position] for position in winnow(first_hashes)}
    selected_second = {second_hashes[position] for position in winnow(second_hashes)}
    assert selected_first & selected_second


def test_hashes_are_the_same_in_every_process_and_shorter_streams_have_none() -> None:
    tokens = ("For", "ID", "Call", "range") * 4
    assert kgram_hashes(tokens) == [166895172525327973]  # blake2b per token: no PYTHONHASHSEED dependence
    assert kgram_hashes(tokens[: K - 1]) == []
    assert winnow([]) == []
