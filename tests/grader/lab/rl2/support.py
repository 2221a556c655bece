"""Judge a check of the second lab on a function run in this process (no sandbox): each planned call made
with the table an `MdpArgument` gives, its value sent through the wire's encoding and back, as the sandbox
would hand it to the check."""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any

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
