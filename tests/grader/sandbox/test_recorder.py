"""The episode recorder and seeding, observed through a real child process over the real protocol."""

from __future__ import annotations

import math
import textwrap
from array import array
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import pytest
from child_client import ChildClient, write_submission

from grader.sandbox.child.budget import structural_count
from grader.sandbox.child.episode_fields import EPISODE_FIELDS
from grader.sandbox.child.frames import decode_value, encode_frame, encode_value
from grader.sandbox.child.log_block import log_block
from grader.sandbox.child.recorder import EpisodeRecord, MadeEnv, Recorder, RecordingEnv
from grader.sandbox.child.seeding import derive_call_seed, reset_seeds
from grader.sandbox.episode_log import EpisodeLog, episodes_from_plain
from grader.sandbox.replay import replay_episode, replay_past_time_limit, verify_reset_seeds

STUDENT = textwrap.dedent("""
    import random

    import gym
    import gymnasium
    import numpy as np

    SHARED = gym.make("Taxi-v3")
    UNSEEDED = np.random.default_rng()
    SEEDED = np.random.default_rng(42)
    SPACE = gymnasium.spaces.Discrete(1000)


    def module_generators():
        return [float(UNSEEDED.random()), float(SEEDED.random()), int(SPACE.sample())]


    def classic_blackjack(n):
        env = gym.make("Blackjack-v0")
        wins = 0
        for _ in range(n):
            env.reset()
            done = False
            while not done:
                observation, reward, done, info = env.step(env.action_space.sample())
            wins += reward > 0
        env.close()
        return wins / n


    def gymnasium_cartpole():
        env = gymnasium.make("CartPole-v1")
        observation, info = env.reset()
        steps, done = 0, False
        while not done:
            observation, reward, terminated, truncated, info = env.step(int(observation[3] > 0))
            steps, done = steps + 1, terminated or truncated
        return steps


    def gymnasium_lab_ids():
        taxi = gymnasium.make("Taxi-v3")
        taxi.reset()
        blackjack = gymnasium.make("Blackjack-v0")
        blackjack.reset()
        return 0


    def gymnasium_retired_id():
        gymnasium.make("Taxi-v2")


    def classic_env_env_without_time_limit():
        env = gym.make("FrozenLake-v0", is_slippery=False).env  # the 2018 lab's idiom
        env.reset()
        dones = [env.step(0)[2] for _ in range(120)]  # left at the start: against the wall
        for action in (1, 1, 2, 1, 2, 2):  # down, down, right, down, right, right: the goal
            observation, reward, done, _ = env.step(action)
        return [any(dones), env.nS, observation, reward, done]


    def gymnasium_env_env_without_time_limit():
        made = gymnasium.make("FrozenLake-v1", is_slippery=False)
        env = made.env  # gymnasium 0.29's idiom: the OrderEnforcing wrapper below the time limit
        table = env.P
        env.reset()
        flags = [env.step(0)[2:4] for _ in range(120)]  # left at the start: against the wall
        for action in (1, 1, 2, 1, 2, 2):  # down, down, right, down, right, right: the goal
            observation, reward, terminated, truncated, _ = env.step(action)
        raw = made.env.env.env  # the raw env at the chain's bottom, stepped directly: still recorded
        raw.reset()
        raw.step(1)
        return [len(table), any(any(pair) for pair in flags), observation, reward, terminated, truncated]


    def gymnasium_frozen_lake_table():
        env = gymnasium.make("FrozenLake-v1", map_name="8x8", is_slippery=True)
        table = env.P  # the second lab's texts read P on gym.make's env
        return [len(table), len(table[0][0]), env.nrow, env.observation_space.n]


    def private_attribute():
        env = gymnasium.make("FrozenLake-v1")
        try:
            env._secret_of_the_env
        except AttributeError as error:
            return str(error)  # caught here: a traceback would keep the env alive into later calls


    def from_spec():
        first = gymnasium.make(gymnasium.spec("CartPole-v0"))
        second = gymnasium.spec("MountainCar-v0").make()
        third = gymnasium.make("gymnasium.envs.classic_control:Acrobot-v1")
        for env in (first, second, third):
            env.reset()
            env.step(0)
        return 0


    def seeded(seed):
        env = gymnasium.make("CartPole-v1")
        first, _ = env.reset(seed=seed)
        env.step(0)
        env.reset()
        second, _ = env.reset(seed=seed)
        return [first.tolist(), second.tolist()]


    def seeded_once(seed):
        if seed == "numpy 5":
            seed = np.int64(5)
        elif seed == "object":
            seed = object()
        env = gymnasium.make("CartPole-v1")
        env.reset(seed=seed)
        env.step(0)
        return 1


    def randoms():
        space = gymnasium.spaces.Discrete(1000)
        return [random.random(), float(np.random.rand()), float(np.random.default_rng().random()),
                int(space.sample())]


    def shared_env():
        return [int(SHARED.reset()), [int(SHARED.action_space.sample()) for _ in range(5)]]


    def after_done():
        env = gym.make("CartPole-v0")
        env.reset()
        done, steps = False, 0
        while not done:
            _, _, done, _ = env.step(0)
        for _ in range(3):
            env.step(1)
        return 0


    def before_reset():
        env = gym.make("Blackjack-v0")
        env.step(0)
        return 0


    def rendering():
        env = gym.make("CartPole-v0", render_mode="human")
        env.reset()
        env.render()
        return env.unwrapped.render_mode


    def time_limit():
        env = gymnasium.make("CartPole-v0", max_episode_steps=5)
        env.reset()
        steps = 0
        truncated = terminated = False
        while not (terminated or truncated):
            _, _, terminated, truncated, _ = env.step(steps % 2)
            steps += 1
        return steps


    def box_actions():
        env = gym.make("GuessingGame-v0")
        env.reset()
        env.step(np.array([0.5], dtype=np.float32))
        env.step(np.array([-3.0]))
        return 0


    def scouting(resets, seed=None):
        env = gymnasium.make("CartPole-v1")
        for _ in range(resets):
            env.reset(seed=seed)
        env.reset()
        for _ in range(5):
            env.step(0)
        return 0


    def stepping(steps):
        env = gymnasium.make("Taxi-v3")
        env.reset()
        for _ in range(steps):
            env.step(0)
        return 0


    def long_run():
        env = gym.make("CartPole-v0")
        for _ in range(10):
            env.reset()
            done = False
            while not done:
                _, _, done, _ = env.step(env.action_space.sample())
        return 0
""")


@pytest.fixture(scope="module")
def submission(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_submission(tmp_path_factory.mktemp("recorder"), STUDENT)


@pytest.fixture(scope="module")
def child(submission: Path) -> Iterator[ChildClient]:
    with ChildClient(submission) as client:
        yield client


def episodes_of(result: dict[str, Any] | None) -> list[EpisodeLog]:
    assert result is not None and result["status"] == "ok", result and result["message"]
    return episodes_from_plain(result["episodes"])


def value_of(result: dict[str, Any] | None) -> Any:
    assert result is not None and result["status"] == "ok", result and result["message"]
    return decode_value(result["value"])


def test_classic_api_code_is_recorded_with_the_lab_id(child: ChildClient) -> None:
    result = child.call("classic_blackjack", 20, seed=11)
    episodes = episodes_of(result)

    assert len(episodes) == 20
    assert {(log.requested_id, log.env_id) for log in episodes} == {("Blackjack-v0", "Blackjack-v1")}
    assert episodes[0].env_kwargs == {"natural": False, "sab": False}
    assert all(log.terminated[-1] for log in episodes)
    wins = sum(log.rewards[-1] > 0 for log in episodes)
    assert decode_value(result["value"]) == wins / 20
    assert verify_reset_seeds(episodes, 11) is None


def test_gymnasium_api_code_is_recorded(child: ChildClient) -> None:
    result = child.call("gymnasium_cartpole", seed=5)
    (log,) = episodes_of(result)

    assert (log.requested_id, log.env_id, log.env_kwargs) == ("CartPole-v1", "CartPole-v1", {})
    assert log.steps == decode_value(result["value"])
    assert log.reset_seed == reset_seeds(5, 1)[0] and log.student_seed is None
    assert all(type(action) is int for action in log.actions)


def test_lab_ids_work_through_plain_gymnasium_and_are_reported(child: ChildClient) -> None:
    result = child.call("gymnasium_lab_ids", seed=3)
    taxi, blackjack = episodes_of(result)

    assert (taxi.requested_id, taxi.env_id, taxi.env_kwargs) == ("Taxi-v3", "Taxi-v4", {})
    assert (blackjack.requested_id, blackjack.env_id) == ("Blackjack-v0", "Blackjack-v1")
    assert blackjack.env_kwargs == {"natural": False, "sab": False}
    assert [event["env_id"] for event in result["compat_events"]] == ["Taxi-v3", "Blackjack-v0"]


def test_retired_ids_through_plain_gymnasium_name_the_lab_id(child: ChildClient) -> None:
    result = child.call("gymnasium_retired_id", seed=3)

    assert result is not None and result["status"] == "exception"
    assert "Taxi-v2 was retired before this lab; the lab uses Taxi-v3" in result["message"]


def test_env_attributes_are_read_through_gymnasium_s_wrappers_and_reported(child: ChildClient) -> None:
    result = child.call("gymnasium_frozen_lake_table", seed=1)
    assert value_of(result) == [64, 3, 8, 64]
    events = {event["env_id"]: event["detail"] for event in result["compat_events"]}  # type: ignore[index]
    assert events["FrozenLake-v1: env.P"] == (
        "env.P was read through gymnasium's wrappers, which gymnasium 1.x no longer forwards; the grader "
        "forwarded it (env.unwrapped.P works everywhere)"
    )
    assert "FrozenLake-v1: env.nrow" in events


def test_classic_env_env_runs_past_the_time_limit_and_replays(child: ChildClient) -> None:
    result = child.call("classic_env_env_without_time_limit", seed=2)
    assert value_of(result) == [False, 16, 15, 1.0, True]
    (log,) = episodes_of(result)
    assert log.steps == 126 and log.truncated[99] and log.rewards[-1] == 1.0
    replayed = replay_episode(log)
    # The log agrees with the real env step for step; the replay's episode ends where gym.make's limit cut
    # it (step 100), and the 26 steps the view took past it are counted, not lost.
    assert (replayed.matches, replayed.length, replayed.steps_after_done) == (True, 100, 26)


def test_gymnasium_env_env_and_the_raw_level_are_recorded_without_the_time_limit(child: ChildClient) -> None:
    result = child.call("gymnasium_env_env_without_time_limit", seed=2)
    assert value_of(result) == [16, False, 15, 1.0, True, False]
    below, raw = episodes_of(result)
    # The log keeps the made env's flags (the limit's truncation from step 100); the student never saw it,
    # and the episode replays to its end past the limit.
    assert (below.steps, below.truncated[99], below.rewards[-1]) == (126, True, 1.0)
    whole = replay_past_time_limit(below)
    assert (whole.matches, whole.length, whole.total_reward) == (True, 126, 1.0)
    assert (raw.steps, replay_episode(raw).matches) == (1, True)


def test_private_env_attributes_are_not_forwarded(child: ChildClient) -> None:
    result = child.call("private_attribute", seed=1)
    assert (
        value_of(result)
        == "accessing private attribute '_secret_of_the_env' of a gym environment is prohibited"
    )


def test_envs_made_from_specs_are_recorded(child: ChildClient) -> None:
    episodes = episodes_of(child.call("from_spec"))

    assert [(log.env_id, log.env_kwargs, log.steps) for log in episodes] == [
        ("CartPole-v0", {}, 1),
        ("MountainCar-v0", {}, 1),
        ("Acrobot-v1", {}, 1),
    ]
    assert [log.env_index for log in episodes] == [0, 1, 2]


def test_student_seeds_are_replaced_by_the_grader_s_next_seeds(child: ChildClient) -> None:
    first = child.call("seeded", 42, seed=7)
    again = child.call("seeded", 42, seed=7)
    episodes = episodes_of(first)

    assert [(log.student_seed, log.reset_seed) for log in episodes] == [
        (42, reset_seeds(7, 3)[0]),
        (None, reset_seeds(7, 3)[1]),
        (42, reset_seeds(7, 3)[2]),
    ]
    observations = decode_value(first["value"])  # type: ignore[index]
    assert observations[0] != observations[1]  # the same student seed no longer picks the same start
    assert decode_value(again["value"]) == observations  # type: ignore[index]
    assert verify_reset_seeds(episodes, 7) is None
    (event,) = [event for event in first["compat_events"] if event["kind"] == "seed_replaced"]  # type: ignore[union-attr]
    assert event["detail"].startswith("reset(seed=...) with your seed 42 was given the grader's next seed")


@pytest.mark.parametrize(
    ("seed", "logged"),
    [(True, None), (2.5, None), (-3, None), (2**70, None), ("7", None), ("numpy 5", 5), ("object", None)],
    ids=["True", "float", "negative", "huge", "str", "numpy int", "object"],
)
def test_every_seed_value_is_recorded_and_replaced(
    child: ChildClient, seed: object, logged: int | None
) -> None:
    result = child.call("seeded_once", seed, seed=7)
    (log,) = episodes_of(result)
    assert (log.student_seed, log.reset_seed) == (logged, reset_seeds(7, 1)[0])


def test_randomness_is_reproducible_per_call_seed_and_differs_between_calls(submission: Path) -> None:
    seeds = (derive_call_seed(3, 0), derive_call_seed(3, 1))
    with ChildClient(submission) as one, ChildClient(submission, seed=99) as other:
        values = [[value_of(client.call("randoms", seed=seed)) for seed in seeds] for client in (one, other)]
        shared = [value_of(client.call("shared_env", seed=4)) for client in (one, other, one)]

    assert values[0] == values[1]
    assert all(first != second for first, second in zip(*values[0], strict=True))
    assert shared[0] == shared[1] == shared[2]


def test_generators_made_at_import_restart_at_every_call(submission: Path) -> None:
    with ChildClient(submission) as one, ChildClient(submission, seed=99) as other:
        first = [value_of(one.call("module_generators", seed=seed)) for seed in (4, 4, 5)]
        fresh = value_of(other.call("module_generators", seed=4))

    assert first[0] == first[1] == fresh
    assert first[0][0] != first[2][0] and first[0][2] != first[2][2]
    assert first[0][1] == first[2][1] == float(np.random.default_rng(42).random())


def test_identical_logs_for_identical_seeds(submission: Path, child: ChildClient) -> None:
    with ChildClient(submission) as fresh:
        first = fresh.call("classic_blackjack", 30, seed=123)
    second = child.call("classic_blackjack", 30, seed=123)
    different = child.call("classic_blackjack", 30, seed=124)

    assert episodes_of(first) == episodes_of(second)
    assert episodes_of(first) != episodes_of(different)


def test_steps_after_done_are_kept(child: ChildClient) -> None:
    (log,) = episodes_of(child.call("after_done"))
    done_at = next(
        index for index, (te, tr) in enumerate(zip(log.terminated, log.truncated, strict=True)) if te or tr
    )

    assert log.steps == done_at + 1 + 3
    assert log.actions[-3:] == [1, 1, 1]


def test_step_before_reset_records_the_implicit_reset(child: ChildClient) -> None:
    result = child.call("before_reset")
    (log,) = episodes_of(result)

    assert log.steps == 1
    assert result is not None
    kinds = [event["kind"] for event in result["compat_events"]]
    assert kinds == ["renamed_id", "api_detected", "step_before_reset"]


def test_human_rendering_is_harmless_and_not_logged(child: ChildClient) -> None:
    result = child.call("rendering")
    (log,) = episodes_of(result)

    assert result is not None and decode_value(result["value"]) is None
    assert "render_mode" not in log.env_kwargs


def test_max_episode_steps_is_logged_for_the_replay(child: ChildClient) -> None:
    (log,) = episodes_of(child.call("time_limit"))

    assert log.env_kwargs == {"max_episode_steps": 5}
    assert log.truncated == [False, False, False, False, True]


def test_box_actions_keep_their_dtype(child: ChildClient) -> None:
    (log,) = episodes_of(child.call("box_actions"))

    assert [action.dtype.str for action in log.actions] == ["<f4", "<f8"]
    assert [action.tolist() for action in log.actions] == [[0.5], [-3.0]]


def test_record_false_sends_no_episodes(child: ChildClient) -> None:
    assert episodes_of(child.call("classic_blackjack", 5, record=False)) == []


def test_too_many_recorded_steps_is_output_too_large(submission: Path) -> None:
    with ChildClient(submission, extra_args=("--max-recorded-steps", "50")) as client:
        result = client.call("long_run")
        unrecorded = client.call("long_run", record=False)

    assert result is not None and result["status"] == "output_too_large"
    assert result["message"] == (
        "long_run() took more than 50 environment steps while the grader records episodes; "
        "play fewer episodes"
    )
    assert unrecorded is not None and unrecorded["status"] == "ok"


def test_results_larger_than_a_frame_are_output_too_large(submission: Path) -> None:
    with ChildClient(submission, extra_args=("--max-frame", "2000")) as client:
        result = client.call("classic_blackjack", 200)

    assert result is not None and result["status"] == "output_too_large"
    assert result["message"].startswith("the episodes classic_blackjack() played need about ")
    assert result["message"].endswith(" bytes, more than the limit of 2000 bytes; play fewer episodes")


def short_episodes(count: int, steps: int = 2) -> Recorder:
    recorder = Recorder(seed=3)
    for number in range(count):
        episode = EpisodeRecord(
            number % 2, "Blackjack-v0", "Blackjack-v1", {"natural": False, "sab": False}, number, None, None
        )
        for _ in range(steps):
            episode.actions.append(1)
            episode.rewards.append(0.0)
            episode.terminated.append(False)
            episode.truncated.append(False)
        recorder.episodes.append(episode)
    return recorder


@pytest.mark.slow  # records up to a hundred thousand episodes
@pytest.mark.parametrize("count", [1, 100, 100_000], ids=["one", "hundred", "hundred-thousand"])
def test_a_calls_log_takes_the_same_few_json_elements_however_many_episodes_it_holds(count: int) -> None:
    episodes = short_episodes(count).finish_call()

    block = log_block(episodes)
    frame = encode_frame({"episodes": encode_value(block, "the episode log")})

    assert structural_count(frame[4:]) < 100  # a table entry and a dozen arrays, none per episode
    assert (block["envs"], block["made"].tolist()) == (
        [
            {
                "requested_id": "Blackjack-v0",
                "env_id": "Blackjack-v1",
                "env_kwargs": {"natural": False, "sab": False},
            }
        ],
        [0] * count,
    )
    assert (block["actions"].dtype, block["rewards"].dtype, len(block["actions"])) == (
        np.int8,
        np.int8,
        2 * count,
    )
    assert episodes_from_plain(encode_value(block)) == [
        EpisodeLog(
            **{name: getattr(episode, name) for name in EPISODE_FIELDS}
            | {"actions": [1, 1], "rewards": [0.0, 0.0], "terminated": [False] * 2, "truncated": [False] * 2}
        )
        for episode in episodes
    ]


BUDGET = {"max_episodes": 4, "max_steps": 20}


@pytest.mark.parametrize(
    ("function", "args", "message"),
    [
        (
            "scouting",
            (3000,),
            "scouting() played 1 game in one call (it reset its environment 3,001 times); "
            "the grader records at most 4 resets per call of scouting()",
        ),
        (
            "scouting",
            (4, True),  # seed=True is not logged (not a grader-mapped seed), but still counted
            "scouting() played 1 game in one call (it reset its environment 5 times); "
            "the grader records at most 4 resets per call of scouting()",
        ),
        (
            "stepping",
            (25,),
            "stepping() took 25 environment steps in one call (over 1 game); "
            "the grader records at most 20 steps per call of stepping()",
        ),
    ],
    ids=["zero-step-resets", "unlogged-resets", "steps"],
)
def test_a_call_beyond_its_budget_ends_with_episode_limit(
    child: ChildClient, function: str, args: tuple[Any, ...], message: str
) -> None:
    result = child.call(function, *args, budget=BUDGET)

    assert result is not None and result["status"] == "episode_limit"
    assert result["message"] == message
    assert result["episodes"] == []


def test_every_reset_within_the_budget_is_recorded(child: ChildClient) -> None:
    logs = episodes_of(child.call("scouting", 3, budget=BUDGET))

    assert [log.steps for log in logs] == [0, 0, 0, 5]


def test_an_unlimited_call_keeps_the_global_limit(child: ChildClient) -> None:
    assert len(episodes_of(child.call("scouting", 3000))) == 3001


def test_int_actions_stay_one_int64_column_until_an_action_that_is_not_such_an_int() -> None:
    record = EpisodeRecord(0, "Taxi-v3", "Taxi-v4", {}, 1, None, None)
    for action in (1, np.int64(2), 3):
        record.add_action(action)
    assert isinstance(record.actions, array) and record.actions.tolist() == [1, 2, 3]

    record.add_action(2**70)  # beyond int64: the column becomes a list, nothing lost
    record.add_action(True)
    assert record.actions == [1, 2, 3, 2**70, True] and type(record.actions[-1]) is bool


class _OddRewards(gymnasium.Env[int, int]):
    """An env whose rewards and flags are not the plain floats and bools gymnasium's own envs return."""

    observation_space = gymnasium.spaces.Discrete(2)
    action_space = gymnasium.spaces.Discrete(2)

    def __init__(self, rewards: list[Any]) -> None:
        self._rewards = iter(rewards)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[int, dict[str, Any]]:
        super().reset(seed=seed)
        return 0, {}

    def step(self, action: int) -> tuple[int, Any, Any, bool, dict[str, Any]]:
        return 0, next(self._rewards), np.bool_(False), False, {}


def test_recorded_steps_log_any_reward_as_a_float_and_nan_when_it_is_not_a_number() -> None:
    recorder = Recorder(seed=1)
    recorder.begin_call(2, record=True)
    env = RecordingEnv(
        _OddRewards(["1.5", 3, np.float32(0.5), object(), 2**2000]), recorder, MadeEnv("Odd", "Odd", {})
    )
    env.reset()
    for action in (0, 1, 1, 0, 1):
        env.step(action)
    (episode,) = recorder.finish_call()

    rewards = episode.rewards.tolist()
    assert rewards[:3] == [1.5, 3.0, 0.5] and math.isnan(rewards[3]) and math.isnan(rewards[4])
    assert list(episode.terminated) == [0] * 5 and episode.actions.tolist() == [0, 1, 1, 0, 1]
    assert (recorder.steps, recorder.played, recorder.resets) == (5, 1, 1)
