"""Batched replay: many episodes of one env at once, bit-identical to gymnasium's scalar env."""

from grader.sandbox.batched.blackjack import BlackjackReplayer
from grader.sandbox.batched.cartpole import CartPoleReplayer
from grader.sandbox.batched.replayer import BatchedEpisode, BatchedReplayer
from grader.sandbox.batched.taxi import TaxiReplayer

REPLAYERS: tuple[BatchedReplayer, ...] = (CartPoleReplayer(), TaxiReplayer(), BlackjackReplayer())
"""Tried in order for each log; a log no replayer accepts is replayed by the scalar env."""

__all__ = [
    "REPLAYERS",
    "BatchedEpisode",
    "BatchedReplayer",
    "BlackjackReplayer",
    "CartPoleReplayer",
    "TaxiReplayer",
]
