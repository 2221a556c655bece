"""Episode logs decoded from the result channel: the child's layout is accepted, anything else refused."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from grader.sandbox.child.episode_fields import EPISODE_COLUMNS, EPISODE_HEADER, SHORT_EPISODE_STEPS
from grader.sandbox.child.errors import InvalidEpisodeLogError
from grader.sandbox.child.frames import encode_frame, encode_value, parse_payload
from grader.sandbox.child.recorder import EpisodeRecord
from grader.sandbox.episode_log import EpisodeLog, WireEpisode, episodes_from_plain
from grader.sandbox.limits import CallBudget

STEPS = [(1, -1.0), (4, -10.0), (5, 20.0)]
LONG = SHORT_EPISODE_STEPS + 1
"""Steps of an episode long enough to send its columns as arrays."""


def recorded(repeats: int = 1) -> EpisodeRecord:
    record = EpisodeRecord(0, "Taxi-v3", "Taxi-v4", {}, 12, None, None)
    for action, reward in STEPS * repeats:
        record.actions.append(action)
        record.rewards.append(reward)
        record.terminated.append(reward == 20.0)
        record.truncated.append(False)
    return record


def wire(**changes: Any) -> Any:
    """`recorded()` on the wire with fields replaced (tagged dicts as given: `encode_value` refuses them)."""
    (plain,) = encode_value([recorded().to_plain()])
    for name, value in changes.items():
        tagged = type(value) is dict and any(key.startswith("$") for key in value)
        plain[name] = value if tagged else encode_value(value)
    return [plain]


@pytest.mark.parametrize("repeats", [1, LONG], ids=["short-lists", "long-arrays"])
def test_the_childs_layout_decodes_to_episode_logs(repeats: int) -> None:
    (log,) = episodes_from_plain(encode_value([recorded(repeats).to_plain()]))

    assert log == EpisodeLog(
        0,
        "Taxi-v3",
        "Taxi-v4",
        {},
        12,
        None,
        [1, 4, 5] * repeats,
        [-1.0, -10.0, 20.0] * repeats,
        [False, False, True] * repeats,
        [False, False, False] * repeats,
    )
    assert all(type(reward) is float for reward in log.rewards)
    assert all(type(action) is int for action in log.actions)
    assert all(type(flag) is bool for flag in log.terminated + log.truncated)


def test_the_parents_model_declares_exactly_the_childs_episode_fields() -> None:
    assert tuple(WireEpisode.__annotations__) == EPISODE_HEADER + EPISODE_COLUMNS
    assert tuple(recorded().to_plain()) == EPISODE_HEADER + EPISODE_COLUMNS
    assert set(EpisodeLog.__dataclass_fields__) == set(EPISODE_HEADER + EPISODE_COLUMNS)


def test_long_episodes_use_small_dtypes() -> None:
    plain = recorded(LONG).to_plain()

    assert (plain["actions"].dtype, plain["rewards"].dtype) == (np.int8, np.int8)


def test_short_episodes_use_lists_with_integral_rewards_as_ints() -> None:
    plain = recorded().to_plain()

    assert (plain["actions"], plain["rewards"], plain["terminated"]) == (
        [1, 4, 5],
        [-1, -10, 20],
        [False, False, True],
    )
    assert [type(reward) for reward in plain["rewards"]] == [int, int, int]


@pytest.mark.parametrize(
    "reward",
    [0.5, -0.0, 2.0**60, float("nan"), float("inf"), float("-inf")],
    ids=["fraction", "negative-zero", "huge", "nan", "inf", "minus-inf"],
)
def test_short_episode_rewards_survive_the_wire(reward: float) -> None:
    record = EpisodeRecord(0, "Taxi-v3", "Taxi-v4", {}, 12, None, None)
    record.actions.append(0)
    record.rewards.append(reward)
    record.terminated.append(False)
    record.truncated.append(True)

    (log,) = episodes_from_plain(
        parse_payload(encode_frame({"e": encode_value([record.to_plain()])})[4:])["e"]
    )

    assert type(log.rewards[0]) is float
    assert log.rewards[0] == reward or (math.isnan(reward) and math.isnan(log.rewards[0]))
    assert (log.terminated, log.truncated) == ([False], [True])


def test_an_empty_episode_decodes() -> None:
    record = EpisodeRecord(1, "CartPole-v0", "CartPole-v0", {}, 3, 5, None)

    (log,) = episodes_from_plain(encode_value([record.to_plain()]))

    assert (log.steps, log.student_seed, log.rewards) == (0, 5, [])


REFUSED = [
    ({"reset_seed": -1}, "episode 0: reset_seed: should be greater than or equal to 0, found int -1"),
    ({"reset_seed": 1.5}, "episode 0: reset_seed: should be a valid integer, found float 1.5"),
    ({"env_index": True}, "episode 0: env_index: should be a valid integer, found bool True"),
    ({"env_id": ""}, "episode 0: env_id: String should have at least 1 character, found str ''"),
    ({"requested_id": "x" * 201}, "episode 0: requested_id: String should have at most 200 characters"),
    ({"env_kwargs": [1]}, "episode 0: env_kwargs: should be a valid dictionary, found list [1]"),
    ({"rewards": np.array([1.0, 2.0])}, "must have one entry per step, found 3, 2, 3 and 3"),
    (
        {"rewards": [1.0, 2.0, "3"]},
        "episode 0: rewards: should be a list of numbers or a numeric array, found list [1.0, 2.0, '3']",
    ),
    ({"rewards": [1.0, 2.0, True]}, "rewards: should be a list of numbers or a numeric array"),
    ({"rewards": [1.0, 2.0]}, "must have one entry per step, found 3, 2, 3 and 3"),
    ({"terminated": [False, 0, True]}, "terminated: should be a list of bools or a bool array"),
    ({"truncated": [False, False]}, "must have one entry per step, found 3, 3, 3 and 2"),
    ({"actions": [1, 2]}, "must have one entry per step, found 2, 3, 3 and 3"),
    ({"terminated": np.array([1, 0, 0])}, "terminated should be a 1-D array of kind 'b'"),
    ({"truncated": np.zeros((3, 1), dtype=bool)}, "truncated should be a 1-D array"),
    ({"actions": np.array([0.5, 1.0, 2.0])}, "actions should be a 1-D array of kind 'iu'"),
    (
        {"actions": "left"},
        "episode 0: actions: should be a list of actions or an int array, found str 'left'",
    ),
    ({"student_seed": "42"}, "episode 0: student_seed: should be a valid integer, found str '42'"),
    ({"reset_options": 3}, "episode 0: reset_options: should be a valid dictionary, found int 3"),
    ({"reset_options": {"$float": "nan"}}, "episode 0: reset_options should be a dict, found float nan"),
    ({"bogus": 1}, "episode 0: 'bogus' is not one of its fields"),
    (
        {"actions": {"$ndarray": {"dtype": "|O", "shape": [3], "data": "AAAA"}}},
        "array dtype '|O' is not a bool/int/float dtype",
    ),
]


@pytest.mark.parametrize(
    ("changes", "message"),
    REFUSED,
    ids=[next(iter(change)) + f"-{index}" for index, (change, _) in enumerate(REFUSED)],
)
def test_malformed_episodes_are_refused(changes: dict[str, Any], message: str) -> None:
    with pytest.raises(InvalidEpisodeLogError) as caught:
        episodes_from_plain(wire(**changes))

    assert message in str(caught.value)
    assert len(str(caught.value)) < 200


@pytest.mark.parametrize(
    ("rewards", "message"),
    [
        ([0, float("nan"), 1], "should be a list of numbers"),
        ([0, 2**5000, 1], "should be a list of numbers"),
        ([0, {"$float": "nan?"}, 1], "should be a list of numbers"),
        ([0, {"$float": "nan", "x": 1}, 1], "should be a list of numbers"),
    ],
    ids=["untagged-nan", "int-beyond-float", "bad-tag", "tag-with-extra-field"],
)
def test_list_rewards_are_refused_unless_numbers_or_tagged_non_finite_floats(
    rewards: list[Any], message: str
) -> None:
    (plain,) = wire()
    plain["rewards"] = rewards

    with pytest.raises(InvalidEpisodeLogError, match=message):
        episodes_from_plain([plain])


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"not": "a list"}, "the episode log: should be a valid list, found dict {'not': 'a list'}"),
        ([{"env_index": 0}], "episode 0: the field 'requested_id' is missing"),
        ([[1, 2]], "episode 0: should be a valid dictionary, found list [1, 2]"),
        (
            [{"$ndarray": {"dtype": "|O", "shape": [1], "data": "AA=="}}],
            "episode 0: the field 'env_index' is missing",
        ),
    ],
    ids=["not-a-list", "missing-fields", "not-a-dict", "object-array"],
)
def test_malformed_episode_lists_are_refused(data: Any, message: str) -> None:
    with pytest.raises(InvalidEpisodeLogError) as caught:
        episodes_from_plain(data)

    assert str(caught.value) == message


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
    ("episodes", "repeats", "budget", "message"),
    [
        (
            5,
            1,
            CallBudget(max_episodes=4, max_steps=100),
            "the log holds 5 episodes, more than the call's limit of 4",
        ),
        (2, 1, CallBudget(max_episodes=4, max_steps=5), "the log holds more than 5 steps, the call's limit"),
        (
            1,
            LONG,
            CallBudget(max_episodes=4, max_steps=50),
            "the log holds more than 50 steps, the call's limit",
        ),
    ],
    ids=["episodes", "steps-in-lists", "steps-in-array-shapes"],
)
def test_logs_beyond_the_calls_budget_are_refused_before_decoding(
    episodes: int, repeats: int, budget: CallBudget, message: str
) -> None:
    data = encode_value([recorded(repeats).to_plain() for _ in range(episodes)])

    with pytest.raises(InvalidEpisodeLogError, match=message):
        episodes_from_plain(data, budget)


def test_logs_within_the_calls_budget_decode() -> None:
    data = encode_value([recorded(LONG).to_plain(), recorded().to_plain()])

    assert len(episodes_from_plain(data, CallBudget(max_episodes=2, max_steps=3 * LONG + 3))) == 2


def test_a_bad_array_is_named_by_its_episode_and_column() -> None:
    data = encode_value([recorded(LONG).to_plain() for _ in range(3)])
    data[1]["truncated"]["$ndarray"]["data"] = "!" * len(data[1]["truncated"]["$ndarray"]["data"])

    with pytest.raises(InvalidEpisodeLogError) as caught:
        episodes_from_plain(data)

    assert str(caught.value) == (
        "the episode log (episode 1: truncated) is not plain data: array data is not valid base64"
    )
