"""Episode logs decoded from the result channel: the child's layout is accepted, anything else refused."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from grader.sandbox.child.errors import InvalidEpisodeLogError
from grader.sandbox.child.protocol import encode_value
from grader.sandbox.child.recorder import EpisodeRecord
from grader.sandbox.episodes import EpisodeLog, episodes_from_plain


def recorded() -> EpisodeRecord:
    record = EpisodeRecord(0, "Taxi-v3", "Taxi-v4", {}, 12, None, None)
    for action, reward in [(1, -1.0), (4, -10.0), (5, 20.0)]:
        record.actions.append(action)
        record.rewards.append(reward)
        record.terminated.append(reward == 20.0)
        record.truncated.append(False)
    return record


def wire(**changes: Any) -> Any:
    plain = {**recorded().to_plain(), **changes}
    return encode_value([plain])


def test_the_childs_layout_decodes_to_episode_logs() -> None:
    (log,) = episodes_from_plain(wire())

    assert log == EpisodeLog(
        0,
        "Taxi-v3",
        "Taxi-v4",
        {},
        12,
        None,
        [1, 4, 5],
        [-1.0, -10.0, 20.0],
        [False, False, True],
        [False, False, False],
    )
    assert all(type(reward) is float for reward in log.rewards)


def test_compact_columns_use_small_dtypes() -> None:
    plain = recorded().to_plain()

    assert (plain["actions"].dtype, plain["rewards"].dtype) == (np.int8, np.int8)


def test_an_empty_episode_decodes() -> None:
    record = EpisodeRecord(1, "CartPole-v0", "CartPole-v0", {}, 3, 5, None)

    (log,) = episodes_from_plain(encode_value([record.to_plain()]))

    assert (log.steps, log.student_seed, log.rewards) == (0, 5, [])


REFUSED = [
    ({"reset_seed": -1}, "episode 0: reset_seed must be an int in [0, 18446744073709551616), found int -1"),
    ({"reset_seed": 1.5}, "reset_seed must be an int"),
    ({"env_index": True}, "env_index must be an int"),
    ({"env_id": ""}, "env_id must be a non-empty str"),
    ({"requested_id": "x" * 201}, "requested_id must be a non-empty str of at most 200"),
    ({"env_kwargs": [1]}, "env_kwargs must be a dict, found list"),
    ({"rewards": np.array([1.0, 2.0])}, "must have one entry per step, found 3, 2, 3 and 3"),
    ({"rewards": [1.0, 2.0, 3.0]}, "rewards must be a 1-D array of kind 'biuf', found list"),
    ({"terminated": np.array([1, 0, 0])}, "terminated must be a 1-D array of kind 'b'"),
    ({"truncated": np.zeros((3, 1), dtype=bool)}, "truncated must be a 1-D array"),
    ({"actions": np.array([0.5, 1.0, 2.0])}, "actions must be a 1-D array of kind 'iu'"),
    ({"actions": "left"}, "actions must be an int array or a list"),
    ({"student_seed": "42"}, "student_seed must be an int"),
    ({"reset_options": 3}, "reset_options must be a dict"),
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


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"not": "a list"}, "episodes must be a list, found dict"),
        ([{"env_index": 0}], "episode 0 must have the fields"),
        ([[1, 2]], "episode 0 must have the fields"),
        ([{"$ndarray": {"dtype": "|O", "shape": [1], "data": "AA=="}}], "not a bool/int/float dtype"),
    ],
    ids=["not-a-list", "missing-fields", "not-a-dict", "object-array"],
)
def test_malformed_episode_lists_are_refused(data: Any, message: str) -> None:
    with pytest.raises(InvalidEpisodeLogError, match=message):
        episodes_from_plain(data)


def test_logs_with_array_actions_compare_by_dtype_and_values() -> None:
    def log(action: np.ndarray) -> EpisodeLog:
        return EpisodeLog(
            0, "GuessingGame-v0", "GuessingGame-v0", {}, 1, None, [action], [0.0], [False], [False]
        )

    same = log(np.array([0.5], dtype=np.float32))

    assert same == log(np.array([0.5], dtype=np.float32))
    assert same != log(np.array([0.5], dtype=np.float64))
    assert same != log(np.array([0.25], dtype=np.float32))
