"""Diagnose gym 0.26 code that ends its episodes on `terminated` alone and so ignores the time limit."""

from __future__ import annotations

from collections.abc import Sequence
from functools import cache

from grader.lab.checks.integrity import Episode
from reference.oracles import random_policy_return

UNLIMITED_STEPS = 40_000
"""Horizon standing in for "no time limit" in the exact random-policy Taxi return (converged by then)."""


@cache
def random_taxi_means() -> tuple[float, float]:
    """Exact mean total reward of random Taxi episodes with the 200-step limit, and without it."""
    return random_policy_return().mean, random_policy_return(max_steps=UNLIMITED_STEPS).mean


def ignored_truncation(episodes: Sequence[Episode]) -> str | None:
    """Why the episodes show a loop that ignored `truncated`, or None.

    The sign: episodes whose replay was cut off by the time limit (truncated, not terminated), after which
    the student kept stepping. Only judged when every episode replayed as logged.
    """
    if any(episode.replay.mismatch for episode in episodes):
        return None
    ignored = [
        episode
        for episode in episodes
        if episode.replay.steps_after_done > 0 and episode.finished and not episode.reached_terminal
    ]
    if not ignored:
        return None
    longest = max(ignored, key=lambda episode: episode.replay.steps_after_done)
    limited, unlimited = random_taxi_means()
    return (
        f"{len(ignored)} episode(s) went on after Taxi's time limit had ended them (truncated=True after {longest.length} steps; e.g. episode {longest.position + 1} of call {longest.call_index + 1} took {longest.replay.steps_after_done} more steps). "  # noqa: E501
        "With gym 0.26's step(), an episode is over when `terminated or truncated`; "
        f"a loop that waits for `terminated` alone ignores the 200-step limit, so random episodes run until the passenger is delivered and average about {unlimited:,.0f} instead of {limited:,.0f}. "  # noqa: E501
        "End the loop with `if terminated or truncated: break`"
    )
