"""An `MdpArgument` in a call's arguments reaches the student's function as a fresh table in the second
lab's format, `{s: {a: [(p, s', r, done), ...]}}` with int keys and tuples of python numbers; on the wire it
is plain lists, decoded within bounds."""

from __future__ import annotations

import json
import textwrap
from pathlib import Path
from typing import Any

import pytest

from grader.sandbox import Call, Limits, OutcomeStatus, Sandbox
from grader.sandbox.child.errors import InvalidValueError
from grader.sandbox.child.frames import (
    MAX_MDP_ACTIONS,
    MAX_MDP_OUTCOMES,
    MAX_MDP_STATES,
    MdpArgument,
    decode_value,
    encode_value,
)
from grader.sandbox.outcome import MdpArgument as Reexported
from reference.oracles.mdps import frozen_lake, lab_example

LIMITS = Limits(call_seconds=20, import_seconds=20, output_bytes=1024, frame_bytes=1 << 20)
EXAMPLE = MdpArgument("the example", lab_example().table)


def _wire(argument: MdpArgument) -> Any:
    return json.loads(json.dumps(encode_value([argument], "the call's arguments")))


def test_it_travels_as_plain_lists_and_comes_back_equal() -> None:
    lake = frozen_lake("4x4", slippery=True)
    argument = MdpArgument(lake.name, lake.table)
    (decoded,) = decode_value(_wire(argument), "the call's arguments", allow_envs=True)
    assert decoded == argument and Reexported is MdpArgument
    table = decoded.as_table()
    assert table == lake.as_dict() and len(table) == 16 and len(table[0]) == 4
    outcome = table[0][0][0]
    assert type(outcome) is tuple and [type(x) for x in outcome] == [float, int, float, bool]
    assert decoded.as_table() is not table and decoded.as_table()[0][0] is not table[0][0]  # fresh each time
    assert repr(argument) == "<P of FrozenLake 4x4 (slippery)>"


def test_it_is_refused_where_a_returned_value_is_decoded() -> None:
    with pytest.raises(InvalidValueError, match="unknown tagged object"):
        decode_value(_wire(EXAMPLE), "the value returned by f()")


def _tampered(change: Any) -> Any:
    wire = _wire(EXAMPLE)
    change(wire[0]["$mdp"])
    return wire


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda spec: spec.pop("name"), "exactly name and table"),
        (lambda spec: spec.update(name=""), "name must be a string"),
        (lambda spec: spec.update(table=[]), "1 to 4096 states"),
        (lambda spec: spec.update(table=[[] for _ in range(3)]), "actions"),
        (lambda spec: spec["table"][1].pop(), "the same 4 actions"),
        (lambda spec: spec["table"][0].__setitem__(0, "x"), "outcomes must be a list"),
        (lambda spec: spec["table"][0][1].__setitem__(0, [1.0, 2, -1.0]), r"\[probability, next_state"),
        (lambda spec: spec["table"][0][1].__setitem__(0, [1.5, 2, -1.0, False]), "not in \\[0, 1\\]"),
        (lambda spec: spec["table"][0][1].__setitem__(0, [1.0, 4, -1.0, False]), "next state 4"),
        (lambda spec: spec["table"][0][1].__setitem__(0, [1.0, True, -1.0, False]), "next state True"),
        (lambda spec: spec["table"][0][1].__setitem__(0, [1.0, 2, "-1", False]), "finite numbers"),
        (lambda spec: spec["table"][0][1].__setitem__(0, [1.0, 2, -1.0, 0]), "terminal flag must be a bool"),
    ],
    ids=[
        "no-name", "empty-name", "no-states", "no-actions", "ragged", "outcomes-not-a-list", "three-fields",
        "probability", "next-state", "bool-state", "text-reward", "int-flag",
    ],
)  # fmt: skip
def test_a_malformed_table_is_refused_with_where_and_what(change: Any, message: str) -> None:
    with pytest.raises(InvalidValueError, match=message):
        decode_value(_tampered(change), "the call's arguments", allow_envs=True)


def test_the_decoded_table_is_bounded() -> None:
    assert (MAX_MDP_STATES, MAX_MDP_ACTIONS) == (4096, 64)
    too_many = [[[[1.0, 0, 0.0, True]] * (MAX_MDP_OUTCOMES // 8 + 1)] * 2] * 4
    with pytest.raises(InvalidValueError, match=f"at most {MAX_MDP_OUTCOMES} outcomes"):
        decode_value([{"$mdp": {"name": "big", "table": too_many}}], "the call's arguments", allow_envs=True)


HOSTILE = textwrap.dedent("""
    def vandal(P, nS, nA):
        seen = [len(P), len(P[0]), sorted(P[1]), [list(o) for o in P[1][1]]]
        for p, s1, r, done in P[2][2]:
            seen.append([p, s1, r, done])
        P[1][1][0] = (1.0, 3, 1000.0, True)   # rewrite an outcome
        P[1][1].append((0.5, 0, 5.0, False))   # and add one
        P.clear()
        return seen
""")


def test_a_call_that_mutates_P_leaves_the_next_call_the_graders_table(tmp_path: Path) -> None:
    submission = tmp_path / "vandal.py"
    submission.write_text(HOSTILE, encoding="utf-8")
    expected = [4, 4, [0, 1, 2, 3], [[1.0, 3, 1.0, True]], [1.0, 3, 1.0, True]]
    with Sandbox(submission, seed=1, limits=LIMITS) as sandbox:
        first = sandbox.call(Call("vandal", (EXAMPLE, 4, 4)))
        second = sandbox.call(Call("vandal", (EXAMPLE, 4, 4)))
    assert first.status is OutcomeStatus.OK and second.status is OutcomeStatus.OK, first.message
    assert first.value == second.value == expected
