"""Judge a check of the second lab on a function run in this process (no sandbox): each planned call made
with the table an `MdpArgument` gives, its value sent through the wire's encoding and back, as the sandbox
would hand it to the check."""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any

import numpy as np

from grader.lab.assignment import load_config
from grader.lab.checks.base import CallRecord, Verdict
from grader.lab.editions import edition_of
from grader.sandbox.child.frames import MdpArgument, decode_value, encode_value
from grader.sandbox.outcome import CallOutcome, OutcomeStatus

SEED = 0
"""The problem seed the in-process tests plan with (the public cases and three held-out random MDPs)."""


def settings(edition: str, problem: str, **changes: Any) -> Any:
    """The problem's settings in the edition's default configuration, with `changes`."""
    pack = edition_of(edition)
    found = pack.registry.problem(problem).settings(load_config(pack.default_config))
    return found.model_copy(update=changes) if changes else found


def outcome(
    call: Any, value: Any = None, status: OutcomeStatus = OutcomeStatus.OK, message: str = ""
) -> CallOutcome:
    return CallOutcome(call, status, value, [], [], "", "", message, 0.0, 0)


def wire(value: Any) -> Any:
    """A returned value as the parent receives it (tuples become lists, numpy scalars python numbers)."""
    return decode_value(json.loads(json.dumps(encode_value(value, "the value"))), "the value")


def judged(
    edition: str, problem: str, function: Callable[..., Any], *, seed: int = SEED, **changes: Any
) -> Verdict:
    """The verdict of `problem` on `function`, every planned call made here (planned with `seed`)."""
    entry = edition_of(edition).registry.problem(problem)
    chosen = settings(edition, problem, **changes)
    records = []
    for call in entry.check.plan(chosen, {}, seed):
        args = [arg.as_table() if isinstance(arg, MdpArgument) else arg for arg in call.args]
        records.append(CallRecord(outcome(call, wire(function(*args))), []))
    return entry.check.judge(chosen, records)


def judged_outcomes(
    edition: str, problem: str, outcomes: Callable[[Any], CallOutcome], *, seed: int = SEED, **changes: Any
) -> Verdict:
    """The verdict of `problem` when each planned call ends as `outcomes(call)` says."""
    entry = edition_of(edition).registry.problem(problem)
    chosen = settings(edition, problem, **changes)
    records = [CallRecord(outcomes(call), []) for call in entry.check.plan(chosen, {}, seed)]
    return entry.check.judge(chosen, records)


def outcome_arrays(P: Any, nS: int, nA: int, read: str = "all") -> tuple[Any, Any, Any]:
    """`P` read into arrays of shape (k, nS, nA): the probability, next state and reward of each move's k-th
    outcome. `read` keeps every outcome ("all"), the first alone ("first": `P[s][a][0]`) or the last alone
    ("last": what `q[a] = ...` for `+=` leaves); a move with fewer outcomes is padded with p = 0, which adds
    0 to its value."""
    moves = [[read_outcomes(P[s][a], read) for a in range(nA)] for s in range(nS)]
    width = max((len(outcomes) for row in moves for outcomes in row), default=0)
    probabilities, rewards = np.zeros((width, nS, nA)), np.zeros((width, nS, nA))
    next_states = np.zeros((width, nS, nA), dtype=np.int64)
    for s, row in enumerate(moves):
        for a, outcomes in enumerate(row):
            for k, (p, s1, r, _) in enumerate(outcomes):
                probabilities[k, s, a], next_states[k, s, a], rewards[k, s, a] = p, s1, r
    return probabilities, next_states, rewards


def read_outcomes(outcomes: Any, read: str) -> list[Any]:
    """The outcomes of one move a student reads: every one, the first alone or the last alone."""
    return list(outcomes[:1] if read == "first" else outcomes[-1:] if read == "last" else outcomes)


def look_ahead(arrays: tuple[Any, Any, Any], V: Any, factor: float) -> Any:
    """`q[s, a]`: each move's `p * (r + factor * V[s'])` added up over its outcomes in their order from 0, as
    the lab's loop over `P[s][a]` adds them (the same sums, number for number, on arrays)."""
    probabilities, next_states, rewards = arrays
    q = np.zeros(probabilities.shape[1:])
    for p, s1, r in zip(probabilities, next_states, rewards, strict=True):
        q = q + p * (r + factor * V[s1])
    return q
