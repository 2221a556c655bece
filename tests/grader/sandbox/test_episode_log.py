"""Episode logs decoded from the result channel: the child's columnar block is accepted, the rest refused."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from grader.sandbox.child.episode_fields import EPISODE_FIELDS, LOG_FIELDS
from grader.sandbox.child.errors import InvalidEpisodeLogError
from grader.sandbox.child.frames import encode_frame, encode_value, parse_payload
from grader.sandbox.child.log_block import NO_EPISODES, log_block
from grader.sandbox.child.recorder import EpisodeRecord
from grader.sandbox.episode_log import (
    _REMEMBERED_KEYS,
    MAX_REMEMBERED_KEY_LENGTH,
    MAX_REMEMBERED_KEYS,
    EpisodeLog,
    WireLog,
    environment_key,
    episodes_from_plain,
)
from grader.sandbox.limits import CallBudget

STEPS = [(1, -1.0), (4, -10.0), (5, 20.0)]


def recorded(
    repeats: int = 1,
    env_index: int = 0,
    kwargs: dict[str, Any] | None = None,
    student_seed: int | None = None,
    options: dict[str, Any] | None = None,
) -> EpisodeRecord:
    record = EpisodeRecord(env_index, "Taxi-v3", "Taxi-v4", kwargs or {}, 12, student_seed, options)
    for action, reward in STEPS * repeats:
        record.actions.append(action)
        record.rewards.append(reward)
        record.terminated.append(reward == 20.0)
        record.truncated.append(False)
    return record


def through_a_frame(records: list[EpisodeRecord]) -> Any:
    """The block as the parent parses it: encoded, framed, parsed."""
    return parse_payload(encode_frame({"e": encode_value(log_block(records))})[4:])["e"]


def wire(**changes: Any) -> Any:
    """Two episodes of `recorded()` on the wire, fields replaced (plain values as given, arrays encoded)."""
    block = encode_value(log_block([recorded(), recorded(env_index=1)]))
    for name, value in changes.items():
        block[name] = encode_value(value) if type(value) is np.ndarray else value
    return block


def played(**fields: Any) -> EpisodeLog:
    header = {
        "env_index": 0,
        "requested_id": "Taxi-v3",
        "env_id": "Taxi-v4",
        "env_kwargs": {},
        "reset_seed": 12,
    }
    columns = {
        "student_seed": None,
        "actions": [1, 4, 5],
        "rewards": [-1.0, -10.0, 20.0],
        "terminated": [False, False, True],
        "truncated": [False, False, False],
    }
    return EpisodeLog(**(header | columns | fields))


def test_the_childs_block_decodes_to_episode_logs() -> None:
    logs = episodes_from_plain(
        through_a_frame(
            [
                recorded(),
                recorded(2, env_index=1, kwargs={"max_episode_steps": 9}, student_seed=2**64 - 1),
                recorded(0, options={"state": [1, 2]}),
            ]
        )
    )

    assert logs == [
        played(),
        played(
            env_index=1,
            env_kwargs={"max_episode_steps": 9},
            student_seed=2**64 - 1,
            actions=[1, 4, 5] * 2,
            rewards=[-1.0, -10.0, 20.0] * 2,
            terminated=[False, False, True] * 2,
            truncated=[False] * 6,
        ),
        played(actions=[], rewards=[], terminated=[], truncated=[], reset_options={"state": [1, 2]}),
    ]
    steps = [value for log in logs for value in log.actions + log.rewards + log.terminated + log.truncated]
    assert {type(value) for value in steps} == {int, float, bool}
    assert all(type(reward) is float for log in logs for reward in log.rewards)


def test_a_call_without_episodes_sends_an_empty_list() -> None:
    assert (
        NO_EPISODES,
        episodes_from_plain([]),
        episodes_from_plain(through_a_frame([])),
        log_block([])["envs"],
    ) == (
        [],
        [],
        [],
        [],
    )


def test_the_parents_model_and_the_childs_block_declare_exactly_the_log_fields() -> None:
    assert tuple(WireLog.__annotations__) == LOG_FIELDS
    assert tuple(log_block([recorded()])) == LOG_FIELDS
    assert set(EpisodeLog.__dataclass_fields__) == set(EPISODE_FIELDS)


def test_the_env_table_holds_each_made_env_once_telling_types_apart() -> None:
    records = [
        recorded(kwargs={"natural": True}),
        recorded(kwargs={"natural": 1}),
        recorded(kwargs={"natural": True}),
    ]

    block = log_block(records)
    logs = episodes_from_plain(encode_value(block))

    assert [entry["env_kwargs"] for entry in block["envs"]] == [{"natural": True}, {"natural": 1}]
    assert block["made"].tolist() == [0, 1, 0]
    assert [(log.env_kwargs, type(log.env_kwargs["natural"])) for log in logs] == [
        ({"natural": True}, bool),
        ({"natural": 1}, int),
        ({"natural": True}, bool),
    ]
    assert logs[0].env_kwargs is not logs[2].env_kwargs  # each episode its own dict


def test_integral_rewards_and_int_actions_use_small_dtypes() -> None:
    block = log_block([recorded(4)])

    assert (block["actions"].dtype, block["rewards"].dtype, block["lengths"].dtype) == (np.int8,) * 3


@pytest.mark.parametrize(
    "reward",
    [0.5, -0.0, 2.0**60, float("nan"), float("inf"), float("-inf")],
    ids=["fraction", "negative-zero", "huge", "nan", "inf", "minus-inf"],
)
def test_rewards_survive_the_wire(reward: float) -> None:
    record = EpisodeRecord(0, "Taxi-v3", "Taxi-v4", {}, 12, None, None)
    record.actions.append(0)
    record.rewards.append(reward)
    record.terminated.append(False)
    record.truncated.append(True)

    (log,) = episodes_from_plain(through_a_frame([record]))

    assert type(log.rewards[0]) is float
    assert log.rewards[0] == reward or (math.isnan(reward) and math.isnan(log.rewards[0]))
    assert (log.terminated, log.truncated) == ([False], [True])


def box(*actions: Any) -> EpisodeRecord:
    record = EpisodeRecord(0, "MountainCarContinuous-v0", "MountainCarContinuous-v0", {}, 3, None, None)
    for action in actions:
        record.add_action(action)
        record.rewards.append(0.0)
        record.terminated.append(False)
        record.truncated.append(False)
    return record


@pytest.mark.parametrize(
    ("records", "form", "expected"),
    [
        (
            [box(np.array([0.5], dtype=np.float32)), box(np.array([-1.0], dtype=np.float32))],
            "array",
            [np.array([0.5], dtype=np.float32), np.array([-1.0], dtype=np.float32)],
        ),
        ([box(np.array(2))], "array", [np.array(2)]),
        (
            [box(np.array([0.5]), np.array([0.5, 1.0]))],
            "plain",
            [np.array([0.5]), np.array([0.5, 1.0])],
        ),
        ([box(np.array([0.5], dtype=np.float32)), box(np.array([0.5]))], "plain", None),
        ([box(1, 0.5, True, [1, 2])], "plain", [1, 0.5, True, [1, 2]]),
        ([box(2**70)], "plain", [2**70]),
        ([box(np.int64(3)), recorded()], "int", [3, 1, 4, 5]),
    ],
    ids=[
        "box-rows",
        "zero-d-arrays",
        "shapes-differ",
        "dtypes-differ",
        "odd-values",
        "big-int",
        "numpy-ints",
    ],
)
def test_actions_that_are_not_plain_ints_travel_in_a_form_that_keeps_them(
    records: list[EpisodeRecord], form: str, expected: list[Any] | None
) -> None:
    block = log_block(records)
    logs = episodes_from_plain(through_a_frame(records))

    actions = [action for log in logs for action in log.actions]
    assert block["action_form"] == form
    assert [log.steps for log in logs] == [len(record.rewards) for record in records]
    if expected is None:
        expected = [action for record in records for action in record.actions]
    assert len(actions) == len(expected)
    for action, wanted in zip(actions, expected, strict=True):
        assert type(action) is type(wanted)
        if type(wanted) is np.ndarray:
            assert (action.dtype, action.shape, action.tolist()) == (
                wanted.dtype,
                wanted.shape,
                wanted.tolist(),
            )
        else:
            assert action == wanted


def array_tag(dtype: str, shape: list[int], data: str = "") -> dict[str, Any]:
    """A tagged array whose data would be refused if decoded: what it announces must refuse it first."""
    return {"$ndarray": {"dtype": dtype, "shape": shape, "data": data}}


REFUSED = [
    pytest.param(
        {"lengths": np.array([3, 2])},
        "the episode log: lengths should sum to the 6 entries of each per-step column, found a sum of 5",
        id="lengths-do-not-sum",
    ),
    pytest.param(
        {"lengths": np.array([2**40, 6 - 2**40])},
        "the episode log: lengths should hold ints from 0 to 6, found -1,099,511,627,770 to 1,099,511,627,776",  # noqa: E501
        id="huge-and-negative-lengths",
    ),
    pytest.param(
        {"lengths": np.array([7, -1])},
        "the episode log: lengths should hold ints from 0 to 6, found -1 to 7",
        id="negative-length",
    ),
    pytest.param(
        {"lengths": np.array([3.0, 3.0])},
        "the episode log: lengths should be 1-D array of kind 'iu', found dtype '<f8' and shape [2]",
        id="float-lengths",
    ),
    pytest.param(
        {"lengths": array_tag("|O", [2], "AAAA")},
        "the episode log: lengths should be 1-D array of kind 'iu', found dtype '|O' and shape [2]",
        id="object-array",
    ),
    pytest.param(
        {"lengths": np.array([[3, 3]])},
        "the episode log: lengths should be 1-D array of kind 'iu', found dtype '<i8' and shape [1, 2]",
        id="two-d-lengths",
    ),
    pytest.param(
        {"terminated": np.array([0, 0, 1, 0, 0, 1], dtype=np.int8)},
        "the episode log: terminated should be 1-D array of kind 'b' of 6 entries, found dtype '|i1' and shape [6]",  # noqa: E501
        id="int-flags",
    ),
    pytest.param(
        {"truncated": np.zeros(5, dtype=bool)},
        "the episode log: truncated should be 1-D array of kind 'b' of 6 entries, found dtype '|b1' and shape [5]",  # noqa: E501
        id="short-flags",
    ),
    pytest.param(
        {"rewards": np.array([True] * 6)},
        "the episode log: rewards should be 1-D array of kind 'iuf', found dtype '|b1' and shape [6]",
        id="bool-rewards",
    ),
    pytest.param(
        {"actions": np.array([0.5] * 6)},
        "the episode log: actions should be 1-D array of kind 'iu' of 6 entries, found dtype '<f8' and shape [6]",  # noqa: E501
        id="float-int-actions",
    ),
    pytest.param(
        {"action_form": "plain"},
        "the episode log: actions sent as plain values should be a list of 6 entries, found dict",
        id="plain-form-with-an-array",
    ),
    pytest.param(
        {"action_form": "plain", "actions": [1, 2]},
        "the episode log: actions sent as plain values should be a list of 6 entries, found list [1, 2]",
        id="plain-list-too-short",
    ),
    pytest.param(
        {"action_form": "plain", "actions": [1, 2, 3, 4, 5, {"$ndarray": 1}]},
        "the episode log (actions)[5] is not plain data: unknown tagged object",
        id="plain-list-bad-tag",
    ),
    pytest.param(
        {"actions": [1] * 6},
        "the episode log: actions of form 'int' should be an array, found a list of 6 entries",
        id="int-form-with-a-list",
    ),
    pytest.param(
        {"action_form": "pickle"},
        "the episode log: action_form: should be 'int', 'array' or 'plain', found str 'pickle'",
        id="unknown-action-form",
    ),
    pytest.param(
        {"made": np.array([0, 1])},
        "the episode log: made should hold ints from 0 to 0, found 0 to 1",
        id="env-table-index-out-of-range",
    ),
    pytest.param(
        {"made": np.array([0])},
        "the episode log: made should be 1-D array of kind 'iu' of 2 entries, found dtype '<i8' and shape [1]",  # noqa: E501
        id="env-table-indices-short",
    ),
    pytest.param(
        {"env_index": np.array([0, -1])},
        "the episode log: env_index should hold ints from 0 to 2,147,483,647, found -1 to 0",
        id="negative-env-index",
    ),
    pytest.param(
        {"env_index": np.array([0, 2**31])},
        "the episode log: env_index should hold ints from 0 to 2,147,483,647, found 0 to 2,147,483,648",
        id="huge-env-index",
    ),
    pytest.param(
        {"reset_seed": np.array([1, -1])},
        "the episode log: reset_seed should hold ints from 0 to 18,446,744,073,709,551,615, found -1 to 1",
        id="negative-seed",
    ),
    pytest.param(
        {"envs": [{"requested_id": "a", "env_id": "b", "env_kwargs": {}}] * 3},
        "the episode log: envs should list at most one env per episode (2), found 3",
        id="env-table-larger-than-the-log",
    ),
    pytest.param(
        {"envs": [{"requested_id": "", "env_id": "b", "env_kwargs": {}}]},
        "the episode log: envs[0].requested_id: String should have at least 1 character, found str ''",
        id="empty-env-id",
    ),
    pytest.param(
        {"envs": [{"requested_id": "a", "env_id": "b", "env_kwargs": [1]}]},
        "the episode log: envs[0].env_kwargs: should be a valid dictionary, found list [1]",
        id="env-kwargs-not-a-dict",
    ),
    pytest.param(
        {
            "student_seed": {
                "episodes": encode_value(np.array([1, 1])),
                "values": encode_value(np.array([5, 6])),
            }
        },
        "the episode log: student_seed.episodes should be strictly increasing episode numbers, found list [1, 1]",  # noqa: E501
        id="sparse-episode-repeated",
    ),
    pytest.param(
        {"student_seed": {"episodes": encode_value(np.array([2])), "values": encode_value(np.array([5]))}},
        "the episode log: student_seed.episodes should hold ints from 0 to 1, found 2 to 2",
        id="sparse-episode-out-of-range",
    ),
    pytest.param(
        {"student_seed": {"episodes": encode_value(np.array([0, 1])), "values": encode_value(np.array([5]))}},
        "the episode log: student_seed should give one value for each of at most 2 episodes, found 2 episodes and 1 values",  # noqa: E501
        id="sparse-values-missing",
    ),
    pytest.param(
        {"reset_options": {"episodes": encode_value(np.array([0])), "values": [{"$float": "nan"}]}},
        "the episode log: episode 0: reset_options should be a dict, found float nan",
        id="options-not-a-dict",
    ),
    pytest.param(
        {"reset_options": {"episodes": encode_value(np.array([0])), "values": [3]}},
        "the episode log: reset_options.values[0]: should be a valid dictionary, found int 3",
        id="options-an-int",
    ),
    pytest.param(
        {"bogus": 1},
        "the episode log: 'bogus' is not one of its fields",
        id="extra-field",
    ),
    pytest.param(
        {"rewards": array_tag("<f8", [6], "!" * 60)},
        "the episode log (rewards) is not plain data: array data of 60 characters cannot hold shape [6] of float64",  # noqa: E501
        id="data-does-not-match-shape",
    ),
    pytest.param(
        {"rewards": array_tag("|i1", [6], "!!!!!!!!")},
        "the episode log (rewards) is not plain data: array data is not valid base64",
        id="bad-base64",
    ),
]


@pytest.mark.parametrize(("changes", "message"), REFUSED)
def test_malformed_blocks_are_refused_saying_what_was_expected_and_found(
    changes: dict[str, Any], message: str
) -> None:
    with pytest.raises(InvalidEpisodeLogError) as caught:
        episodes_from_plain(wire(**changes))

    assert message in str(caught.value)
    assert len(str(caught.value)) < 200


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"not": "a block"}, "the episode log: the field 'envs' is missing"),
        ([{"env_index": 0}], "the episode log: should be a valid dictionary, found list [{'env_index': 0}]"),
        ("episodes", "the episode log: should be a valid dictionary, found str 'episodes'"),
        (None, "the episode log: should be a valid dictionary, found NoneType None"),
    ],
    ids=["missing-fields", "old-per-episode-list", "a-string", "null"],
)
def test_what_is_not_a_block_is_refused(data: Any, message: str) -> None:
    with pytest.raises(InvalidEpisodeLogError) as caught:
        episodes_from_plain(data)

    assert str(caught.value) == message


def test_a_lengths_array_whose_sum_overflows_64_bits_is_refused_without_decoding_the_steps() -> None:
    steps = 2**61
    block = wire(
        lengths=np.array([steps] * 9),
        made=np.zeros(9, dtype=np.int8),
        env_index=np.zeros(9, dtype=np.int8),
        reset_seed=np.zeros(9, dtype=np.uint64),
    )
    for name, dtype in (("actions", "|i1"), ("rewards", "|i1"), ("terminated", "|b1"), ("truncated", "|b1")):
        block[name] = array_tag(dtype, [steps])  # no data: decoding it would fail, and is never tried

    with pytest.raises(InvalidEpisodeLogError) as caught:
        episodes_from_plain(block)

    assert str(caught.value) == (
        "the episode log: lengths should sum to the 2,305,843,009,213,693,952 entries of each per-step column, "  # noqa: E501
        "found a sum of 20,752,587,082,923,245,568"
    )


@pytest.mark.parametrize(
    ("episodes", "steps", "budget", "message"),
    [
        (
            5,
            3,
            CallBudget(max_episodes=4, max_steps=100),
            "the log holds 5 episodes, more than the call's limit of 4",
        ),
        (
            2,
            60,
            CallBudget(max_episodes=4, max_steps=50),
            "the log holds 60 steps, more than the call's limit of 50",
        ),
        (
            2**40,
            3,
            CallBudget(max_episodes=4, max_steps=50),
            "the log holds 1,099,511,627,776 episodes, more than the call's limit of 4",
        ),
        (
            2,
            2**61,
            CallBudget(max_episodes=4, max_steps=50),
            "the log holds 2,305,843,009,213,693,952 steps, more than the call's limit of 50",
        ),
    ],
    ids=["episodes", "steps", "huge-episode-count", "huge-step-count"],
)
def test_logs_beyond_the_calls_budget_are_refused_from_the_announced_shapes(
    episodes: int, steps: int, budget: CallBudget, message: str
) -> None:
    block = wire()
    block["lengths"] = array_tag("|i1", [episodes])  # no data: refused before anything is decoded
    for name, dtype in (("actions", "|i1"), ("rewards", "|i1"), ("terminated", "|b1"), ("truncated", "|b1")):
        block[name] = array_tag(dtype, [steps])

    with pytest.raises(InvalidEpisodeLogError) as caught:
        episodes_from_plain(block, budget)

    assert str(caught.value) == message


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        (
            {"envs": [{"requested_id": "a", "env_id": "b", "env_kwargs": {"x": [1] * 100}}] * 5},
            "the episode log: envs holds 5 entries, more than the call's limit of 4 episodes",
        ),
        (
            {"reset_options": {"episodes": encode_value(np.arange(5)), "values": [{}] * 5}},
            "the episode log: reset_options holds 5 entries, more than the call's limit of 4 episodes",
        ),
    ],
    ids=["env-table", "reset-options"],
)
def test_tables_longer_than_the_calls_episodes_are_refused_before_their_entries_are_validated(
    changes: dict[str, Any], message: str
) -> None:
    with pytest.raises(InvalidEpisodeLogError) as caught:
        episodes_from_plain(wire(**changes), CallBudget(max_episodes=4, max_steps=100))

    assert str(caught.value) == message


def test_logs_within_the_calls_budget_decode() -> None:
    data = encode_value(log_block([recorded(2), recorded()]))

    assert len(episodes_from_plain(data, CallBudget(max_episodes=2, max_steps=9))) == 2


def test_flags_are_bools_whatever_byte_a_forged_array_holds() -> None:
    block = wire(terminated=np.frombuffer(bytes([0, 2, 255, 0, 0, 1]), dtype=np.bool_))

    first, second = episodes_from_plain(block)

    assert (first.terminated, second.terminated) == ([False, True, True], [False, False, True])
    assert {type(flag) for flag in first.terminated + second.terminated} == {bool}


def test_logs_with_array_actions_compare_by_dtype_and_values() -> None:
    def log(action: np.ndarray) -> EpisodeLog:
        return EpisodeLog(
            0, "GuessingGame-v0", "GuessingGame-v0", {}, 1, None, [action], [0.0], [False], [False]
        )

    same = log(np.array([0.5], dtype=np.float32))

    assert same == log(np.array([0.5], dtype=np.float32))
    assert same != log(np.array([0.5], dtype=np.float64))
    assert same != log(np.array([0.25], dtype=np.float32))


@pytest.mark.parametrize(
    ("first", "second"),
    [
        ({"sab": True}, {"sab": 1}),
        ({"sab": 1}, {"sab": True}),
        ({"natural": False}, {"natural": 0}),
        ({"limit": 0}, {"limit": 0.0}),
        ({"limit": 0.0}, {"limit": -0.0}),
        ({"map": [1]}, {"map": [True]}),
        ({"name": None}, {"name": "None"}),
        ({}, {"sab": False}),
    ],
    ids=[
        "True-then-1",
        "1-then-True",
        "False-then-0",
        "int-then-float",
        "zero-then-minus-zero",
        "nested-bool",
        "None-then-text",
        "none-then-one",
    ],
)
def test_environments_whose_arguments_differ_in_type_or_value_have_different_keys(
    first: dict[str, Any], second: dict[str, Any]
) -> None:
    # Each made twice: the second time from what the first made is remembered.
    keys = [environment_key("Blackjack-v1", arguments) for arguments in (first, second, first, second)]
    assert keys[0] == keys[2] != keys[1] == keys[3]


def test_an_environments_key_ignores_the_order_of_its_arguments_and_names_its_id() -> None:
    assert environment_key("Taxi-v4", {"a": 1, "b": "x"}) == environment_key("Taxi-v4", {"b": "x", "a": 1})
    assert environment_key("Taxi-v4", {"a": [1, {"y": 2, "x": 3}]}) == environment_key(
        "Taxi-v4", {"a": [1, {"x": 3, "y": 2}]}
    )
    assert environment_key("Taxi-v4", {}) != environment_key("Taxi-v3", {})


def test_each_logs_environment_is_its_id_and_arguments_key() -> None:
    first, second = episodes_from_plain(
        through_a_frame([recorded(kwargs={"is_rainy": False}), recorded(env_index=1, kwargs={"is_rainy": 0})])
    )
    assert first.environment == environment_key("Taxi-v4", {"is_rainy": False})
    assert second.environment == environment_key("Taxi-v4", {"is_rainy": 0}) != first.environment


def test_what_environment_keys_remember_stays_bounded_and_keys_stay_right() -> None:
    long_name = "x" * (MAX_REMEMBERED_KEY_LENGTH + 1)
    assert environment_key("Taxi-v4", {"name": long_name}) == environment_key("Taxi-v4", {"name": long_name})
    assert all(long_name not in key for key in _REMEMBERED_KEYS.values())
    for number in range(MAX_REMEMBERED_KEYS + 10):
        assert environment_key("Taxi-v4", {"seed": number}) == f'["Taxi-v4", {{"seed": {number}}}]'
    assert 0 < len(_REMEMBERED_KEYS) <= MAX_REMEMBERED_KEYS
