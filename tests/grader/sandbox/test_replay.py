"""Replay in the parent: honest logs match, patched dynamics, time limits and forged logs are caught."""

from __future__ import annotations

import dataclasses
import textwrap
import warnings
from pathlib import Path

import gymnasium
import numpy as np
import pytest
from child_client import ChildClient, write_submission

from grader.sandbox import replay
from grader.sandbox.batched import BatchedReplayer, BlackjackReplayer, CartPoleReplayer, TaxiReplayer
from grader.sandbox.batched.draws import SeededDraws, seeded_draws
from grader.sandbox.child.seeding import reset_seeds
from grader.sandbox.episode_log import EpisodeLog, episodes_from_plain
from grader.sandbox.replay import Replay, replay_episode, replay_episodes, verify_reset_seeds

HONEST = textwrap.dedent("""
    import gym
    import gymnasium
    import numpy as np


    def cartpole():
        env = gym.make("CartPole-v0")
        observation, done, steps = env.reset(), False, 0
        while not done:
            observation, reward, done, info = env.step(1 if observation[3] > 0 else 0)
            steps += 1
        return steps


    def balanced(episodes):
        env = gymnasium.make("CartPole-v1")
        for _ in range(episodes):
            o, _ = env.reset()
            done = False
            while not done:
                o, _, terminated, truncated, _ = env.step(int(o[2] + 0.5 * o[3] > 0))
                done = terminated or truncated
        return 0


    def random_play(episodes):
        env = gym.make("CartPole-v0")
        for _ in range(episodes):
            env.reset()
            for _ in range(40):
                env.step(env.action_space.sample())
        return 0


    def with_options():
        env = gymnasium.make("CartPole-v1")
        env.reset(options={"low": -0.2, "high": 0.2})
        for _ in range(30):
            env.step(1)
        return 0


    def other_games():
        for name in ("Taxi-v3", "Blackjack-v0", "MountainCar-v0", "NChain-v0", "GuessingGame-v0"):
            env = gym.make(name)
            env.reset()
            done, steps = False, 0
            while not done and steps < 300:
                _, _, done, _ = env.step(env.action_space.sample())
                steps += 1
        return 0
""")

PATCHED_PHYSICS = textwrap.dedent("""
    import gym
    from gymnasium.envs.classic_control.cartpole import CartPoleEnv

    original_init = CartPoleEnv.__init__


    def tolerant_init(self, *args, **kwargs):
        original_init(self, *args, **kwargs)
        self.theta_threshold_radians = 1e9
        self.x_threshold = 1e9


    CartPoleEnv.__init__ = tolerant_init


    def cartpole():
        env = gym.make("CartPole-v0")
        observation, done, steps = env.reset(), False, 0
        while not done:
            observation, reward, done, info = env.step(0)
            steps += 1
        return steps
""")

PATCHED_TIME_LIMIT = textwrap.dedent("""
    import gym
    import gymnasium

    gymnasium.envs.registration.registry["CartPole-v0"].max_episode_steps = 500


    def cartpole():
        env = gym.make("CartPole-v0")
        o, done, steps = env.reset(), False, 0
        while not done:
            o, reward, done, info = env.step(int(o[2] + 0.5 * o[3] > 0))
            steps += 1
        return steps
""")


def play(tmp_path: Path, source: str, function: str, *args: object, seed: int = 1) -> list[EpisodeLog]:
    with ChildClient(write_submission(tmp_path, source)) as client:
        result = client.call(function, *args, seed=seed)
    assert result is not None and result["status"] == "ok", result and result["message"]
    return episodes_from_plain(result["episodes"])


@pytest.fixture(scope="module")
def honest_logs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, list[EpisodeLog]]:
    with ChildClient(write_submission(tmp_path_factory.mktemp("honest"), HONEST)) as client:
        results = {
            name: client.call(name, *args, seed=index + 1)
            for index, (name, args) in enumerate(
                [
                    ("cartpole", ()),
                    ("balanced", (3,)),
                    ("random_play", (20,)),
                    ("other_games", ()),
                    ("with_options", ()),
                ]
            )
        }
    logs = {}
    for name, result in results.items():
        assert result is not None and result["status"] == "ok", result and result["message"]
        logs[name] = episodes_from_plain(result["episodes"])
    return logs


@pytest.mark.parametrize("name", ["cartpole", "balanced", "random_play", "other_games", "with_options"])
def test_honest_episodes_replay_without_mismatch(honest_logs: dict[str, list[EpisodeLog]], name: str) -> None:
    for log in honest_logs[name]:
        replay = replay_episode(log)

        assert replay.mismatch is None
        assert replay.rewards == log.rewards[: replay.length]
        assert len(replay.observations) == replay.length + 1
        assert replay.length + replay.steps_after_done == log.steps


def test_honest_cartpole_episode_has_the_reported_length(honest_logs: dict[str, list[EpisodeLog]]) -> None:
    (log,) = honest_logs["cartpole"]
    replay = replay_episode(log)

    assert replay.finished and replay.length == log.steps and replay.steps_after_done == 0
    assert replay.env_spec is not None and replay.env_spec.max_episode_steps == 200


def test_reset_options_are_replayed_and_not_batched(honest_logs: dict[str, list[EpisodeLog]]) -> None:
    (log,) = honest_logs["with_options"]

    assert log.reset_options == {"low": -0.2, "high": 0.2}
    assert not CartPoleReplayer().is_batchable(log)
    assert replay_episode(log).matches


def test_steps_after_done_are_counted(honest_logs: dict[str, list[EpisodeLog]]) -> None:
    replays = [replay_episode(log) for log in honest_logs["random_play"]]

    assert all(replay.matches for replay in replays)
    assert all(replay.length + replay.steps_after_done == 40 for replay in replays)
    assert any(replay.steps_after_done > 0 for replay in replays)


def assert_same_replay(batched: Replay, scalar: Replay) -> None:
    assert np.array_equal(np.array(batched.observations), np.array(scalar.observations))
    assert (batched.rewards, batched.terminated, batched.truncated) == (
        scalar.rewards,
        scalar.terminated,
        scalar.truncated,
    )
    assert (batched.length, batched.finished, batched.steps_after_done, batched.mismatch) == (
        scalar.length,
        scalar.finished,
        scalar.steps_after_done,
        scalar.mismatch,
    )


def test_batched_cartpole_replay_is_identical_to_the_scalar_replay(
    honest_logs: dict[str, list[EpisodeLog]],
) -> None:
    logs = [log for name in ("cartpole", "balanced", "random_play") for log in honest_logs[name]]
    assert all(CartPoleReplayer().is_batchable(log) for log in logs)

    for batched, log in zip(replay_episodes(logs), logs, strict=True):
        assert_same_replay(batched, replay_episode(log))


def played(
    env_id: str, seed: int, actions: list[int], env_kwargs: dict[str, int | bool] | None = None
) -> EpisodeLog:
    """An honest log: `actions` played in a fresh gymnasium env, steps after done included."""
    env = gymnasium.make(env_id, **(env_kwargs or {}))
    env.reset(seed=seed)
    rewards, terminated, truncated = [], [], []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for action in actions:
            _, reward, step_terminated, step_truncated, _ = env.step(action)
            rewards.append(float(reward))
            terminated.append(bool(step_terminated))
            truncated.append(bool(step_truncated))
    return EpisodeLog(
        0, env_id, env_id, env_kwargs or {}, seed, None, actions, rewards, terminated, truncated
    )


BATCHES = [
    (CartPoleReplayer(), "CartPole-v1", 2, 120, None),
    (CartPoleReplayer(), "CartPole-v1", 2, 120, {"max_episode_steps": 15}),
    (TaxiReplayer(), "Taxi-v4", 6, 260, None),
    (TaxiReplayer(), "Taxi-v4", 6, 40, {"max_episode_steps": 30}),
    (BlackjackReplayer(), "Blackjack-v1", 2, 6, {"natural": False, "sab": False}),
    (BlackjackReplayer(), "Blackjack-v1", 2, 6, {"natural": True, "sab": False}),
    (BlackjackReplayer(), "Blackjack-v1", 2, 6, {}),
]


@pytest.mark.parametrize(
    ("replayer", "env_id", "actions", "steps", "env_kwargs"),
    BATCHES,
    ids=[
        "cartpole",
        "cartpole-limit-15",
        "taxi",
        "taxi-limit-30",
        "blackjack-lab",
        "blackjack-natural",
        "blackjack-sab",
    ],
)
def test_batched_replay_matches_the_scalar_env_bit_for_bit(
    replayer: BatchedReplayer,
    env_id: str,
    actions: int,
    steps: int,
    env_kwargs: dict[str, int | bool] | None,
) -> None:
    # Deterministic (fixed seeds): random actions visit many more states than the lab's policies.
    rng = np.random.default_rng(20240601)
    logs = [played(env_id, seed, rng.integers(0, actions, steps).tolist(), env_kwargs) for seed in range(40)]
    assert all(replayer.is_batchable(log) for log in logs)

    for batched, log in zip(replayer.replay(logs), logs, strict=True):
        scalar = replay_episode(log)
        assert scalar.matches
        assert len(batched.observations) == len(scalar.observations)
        assert all(
            np.array_equal(one, other)
            for one, other in zip(batched.observations, scalar.observations, strict=True)
        )
        assert (batched.rewards, batched.terminated, batched.truncated, batched.finished) == (
            scalar.rewards,
            scalar.terminated,
            scalar.truncated,
            scalar.finished,
        )
    for batched, log in zip(replay_episodes(logs), logs, strict=True):
        assert_same_replay(batched, replay_episode(log))


WIDE_SEEDS = [0, 1, 2**32 - 1, 2**32, 2**63 - 1, 2**64 - 1, 2**64, 2**100 + 3, 2**128 - 1]


@pytest.mark.parametrize("mixed", [False, True], ids=["wide-seeds-alone", "wide-seeds-among-stream-seeds"])
def test_seeded_draws_follow_numpys_generators_for_seeds_of_every_width(mixed: bool) -> None:
    # 1 to 4 words of entropy; below 2**64 the seeds are hashed from one uint64 array, above it from lists.
    seeds = [*WIDE_SEEDS, *reset_seeds(5, 200)] if mixed else [seed for seed in WIDE_SEEDS if seed < 2**64]
    for seed, draws in zip(seeds, seeded_draws(seeds), strict=True):
        generator = np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed)))

        assert [draws.random() for _ in range(5)] == [generator.random() for _ in range(5)], seed


def test_seeded_draws_refuse_a_seed_numpy_would_hash_differently() -> None:
    with pytest.raises(ValueError, match=r"seeds in \[0, 2\*\*128\), found -1 to 2"):
        seeded_draws([-1, 2])


BOUNDED_COUNTS = [1, 2, 3, 4, 13, 3 * 2**30, 2**31 + 1, 2**32 - 5, 2**32]


@pytest.mark.parametrize("count", BOUNDED_COUNTS, ids=[str(count) for count in BOUNDED_COUNTS])
def test_card_draws_are_numpys_bounded_draws(count: int) -> None:
    # Counts near 2**32 reject about a third of the draws, so Lemire's rejection loop is exercised.
    for seed in (0, 1, 2**40 + 7, 2**63 - 1):
        generator = np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed)))
        draws = seeded_draws([seed])[0]

        assert [draws.bounded(count) for _ in range(50)] == [
            int(generator.integers(0, count)) for _ in range(50)
        ]


@pytest.mark.parametrize(
    "sequence",
    [[1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 10, 10, 10], ["C", "D", "H", "S"], ["J", "Q", "K"]],
    ids=["deck", "suits", "faces"],
)
def test_card_draws_choose_as_generator_choice_does(sequence: list[object]) -> None:
    generator, _ = gymnasium.utils.seeding.np_random(2024)
    draws = seeded_draws([2024])[0]

    assert [draws.choice(sequence) for _ in range(100)] == [
        generator.choice(sequence).item() for _ in range(100)
    ]


@pytest.mark.parametrize("kept", [0, 1], ids=["rejected", "kept"])
def test_a_card_drawn_after_a_rejected_draw_is_numpys(kept: int) -> None:
    # A kept 32-bit half of 0 makes `choice` of 13 cards reject it and draw again (0 * 13 is below
    # Lemire's threshold for 13, 2**32 % 13 == 9); a half of 1 is used. numpy is set to the same state.
    deck = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 10, 10, 10]
    for seed in (0, 3, 2**50 + 1):
        generator = np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed)))
        draws = seeded_draws([seed])[0]
        generator.integers(0, 13)  # both now keep the high half of their first output
        draws.choice(deck)
        state = generator.bit_generator.state
        generator.bit_generator.state = {**state, "has_uint32": 1, "uinteger": kept}
        draws._kept_half = kept

        assert [draws.choice(deck) for _ in range(20)] == [deck[generator.integers(0, 13)] for _ in range(20)]


def test_seeded_draws_interleave_doubles_and_bounded_draws_as_numpy_does() -> None:
    # A double takes a whole 64-bit output; the high half of an earlier 32-bit draw stays kept.
    operations = [13, "random", 13, 4, "random", "random", 3, 13, 13, 13, "random", 2**32 - 5] * 5
    for seed in (0, 5, 2**62 + 3):
        generator, _ = gymnasium.utils.seeding.np_random(seed)
        draws = seeded_draws([seed])[0]

        expected = [
            generator.random() if op == "random" else int(generator.integers(0, op)) for op in operations
        ]
        assert [draws.random() if op == "random" else draws.bounded(op) for op in operations] == expected


BLACKJACK_RULES = [
    {},
    {"natural": False, "sab": False},
    {"natural": True},
    {"sab": True},
    {"natural": True, "sab": True},
]


@pytest.mark.slow  # replays many seeds per variant, seconds each
@pytest.mark.parametrize(
    "kwargs", BLACKJACK_RULES, ids=["defaults", "plain", "natural", "sab", "natural-sab"]
)
def test_batched_blackjack_matches_gymnasiums_env_over_many_seeds(kwargs: dict[str, bool]) -> None:
    # Deterministic: 3000 grader-stream seeds, random hit/stick sequences (long ones run past the end);
    # about 1 in 20 deals is a natural, so each rule's payout is met about 150 times.
    rng = np.random.default_rng(4096)
    seeds = reset_seeds(77, 3000)
    logs = [played("Blackjack-v1", seed, rng.integers(0, 2, 1 + seed % 7).tolist(), kwargs) for seed in seeds]
    env = gymnasium.make("Blackjack-v1", **kwargs)

    for batched, log in zip(BlackjackReplayer().replay(logs), logs, strict=True):
        observations = [env.reset(seed=log.reset_seed)[0]]
        rewards, terminated = [], []
        for action in log.actions:
            observation, reward, ended, _, _ = env.step(action)
            observations.append(observation)
            rewards.append(float(reward))
            terminated.append(ended)
            if ended:
                break
        assert (batched.observations, batched.rewards, batched.terminated) == (
            observations,
            rewards,
            terminated,
        )
        assert batched.finished == terminated[-1]


def test_a_wrong_batched_blackjack_is_discarded_for_the_scalar_env(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(99)
    logs = [
        played("Blackjack-v1", seed, rng.integers(0, 2, 3).tolist(), {"natural": False, "sab": False})
        for seed in range(50)
    ]
    expected = [replay_episode(log) for log in logs]
    monkeypatch.setattr(SeededDraws, "bounded", lambda self, count: 0)

    assert replay._batch_or_none(BlackjackReplayer(), logs) is None
    for batched, scalar in zip(replay_episodes(logs), expected, strict=True):
        assert_same_replay(batched, scalar)
        assert batched.matches


def test_forged_blackjack_rewards_are_caught_in_a_batch() -> None:
    rng = np.random.default_rng(5)
    kwargs = {"natural": False, "sab": False}
    logs = [played("Blackjack-v1", seed, rng.integers(0, 2, 2).tolist(), kwargs) for seed in range(30)]
    forged = dataclasses.replace(logs[7], rewards=[1.0] * logs[7].steps)
    assert forged.rewards != logs[7].rewards

    replays = replay_episodes([*logs[:7], forged, *logs[8:]])

    assert [replayed.matches for replayed in replays] == [index != 7 for index in range(30)]
    assert replays[7].mismatch == replay_episode(forged).mismatch
    assert replays[7].mismatch is not None and "your code saw reward=1.0" in replays[7].mismatch


def test_replay_stops_at_the_real_end_of_the_episode() -> None:
    rng = np.random.default_rng(7)
    logs = [played("CartPole-v1", seed, rng.integers(0, 2, 1000).tolist()) for seed in range(5)]

    for batched in replay_episodes(logs):
        assert batched.finished and batched.length < 100
        assert batched.steps_after_done == 1000 - batched.length
        assert len(batched.rewards) == batched.length and batched.matches


def test_batches_are_split_to_bound_memory(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(8)
    logs = [played("Taxi-v4", seed, rng.integers(0, 6, 30 + seed).tolist()) for seed in range(30)]
    whole = replay_episodes(logs)
    monkeypatch.setattr(replay, "MAX_BATCH_CELLS", 100)

    for split, one in zip(replay_episodes(logs), whole, strict=True):
        assert_same_replay(split, one)


def test_envs_without_a_time_limit_are_not_batched() -> None:
    log = played("CartPole-v1", 1, [0, 1, 0], {"max_episode_steps": -1})

    assert not CartPoleReplayer().is_batchable(log)
    assert replay_episodes([log])[0].matches


def test_monkeypatched_physics_is_caught(tmp_path: Path) -> None:
    (log,) = play(tmp_path, PATCHED_PHYSICS, "cartpole")
    replay = replay_episode(log)
    (batched,) = replay_episodes([log])

    assert log.steps == 200 and not any(log.terminated)
    assert replay.finished and replay.length < 50
    assert replay.mismatch is not None
    assert replay.mismatch.startswith(
        f"step {replay.length} of the episode in CartPole-v0 "
        f"(gymnasium.make('CartPole-v0')) (reset seed {log.reset_seed}): your code "
        "saw reward=1.0, terminated=False, truncated=False, but the real environment "
        "gives reward=1.0, terminated=True, truncated=False"
    )
    assert batched.mismatch == replay.mismatch


def test_patched_time_limit_is_caught(tmp_path: Path) -> None:
    (log,) = play(tmp_path, PATCHED_TIME_LIMIT, "cartpole")
    replay = replay_episode(log)

    assert log.steps == 500 and log.env_kwargs == {}
    assert replay.length == 200 and replay.truncated[199]
    assert replay.mismatch is not None and replay.mismatch.startswith("step 200 of the episode")
    assert "your code saw reward=1.0, terminated=False, truncated=False" in replay.mismatch
    assert "the real environment gives reward=1.0, terminated=False, truncated=True" in replay.mismatch


FORGERIES = [
    ("rewards", lambda log: {"rewards": [*log.rewards[:-1], 2.0]}, "your code saw reward=2.0"),
    ("terminated", lambda log: {"terminated": [True] * log.steps}, "step 1 of the episode"),
    (
        "truncated",
        lambda log: {"truncated": [True] * log.steps},
        "saw reward=1.0, terminated=False, truncated=True",
    ),
]


@pytest.mark.parametrize(("field", "forge", "seen"), FORGERIES, ids=[forgery[0] for forgery in FORGERIES])
def test_forged_logs_are_caught(
    honest_logs: dict[str, list[EpisodeLog]], field: str, forge: object, seen: str
) -> None:
    (log,) = honest_logs["cartpole"]
    forged = dataclasses.replace(log, **forge(log))  # type: ignore[operator]

    for replayed in (replay_episode(forged), replay_episodes([forged])[0]):
        assert replayed.mismatch is not None and seen in replayed.mismatch
        assert replayed.rewards == log.rewards


def test_a_forged_reset_seed_is_caught_by_the_seed_check(honest_logs: dict[str, list[EpisodeLog]]) -> None:
    logs = honest_logs["random_play"]
    forged = [logs[0], dataclasses.replace(logs[1], reset_seed=12345), *logs[2:]]

    assert verify_reset_seeds(logs, 3) is None
    assert verify_reset_seeds(forged, 3) == (
        f"episode 2 was reset with seed 12345, but the grader's seed stream gives {logs[1].reset_seed}: "
        "the episode log was altered"
    )


UNPLAYABLE = [
    ({"env_id": "antigravity:Fly-v0"}, "'antigravity:Fly-v0' is not a registered gymnasium id"),
    ({"env_id": "CartPole-v0", "env_kwargs": {"render_mode": "human"}}, "are not replayable"),
    ({"env_kwargs": {"no_such_argument": 1}}, "cannot be made: TypeError"),
    ({"actions": [7]}, "the real environment refused the action 7"),
]


@pytest.mark.parametrize(
    ("changes", "message"), UNPLAYABLE, ids=["module-id", "render", "bad-kwarg", "bad-action"]
)
def test_unplayable_logs_give_a_mismatch_not_an_exception(
    honest_logs: dict[str, list[EpisodeLog]], changes: dict[str, object], message: str
) -> None:
    (log,) = honest_logs["cartpole"]
    steps = len(changes.get("actions", log.actions))  # type: ignore[arg-type]
    forged = dataclasses.replace(
        log,
        **{
            "rewards": log.rewards[:steps],
            "terminated": log.terminated[:steps],
            "truncated": log.truncated[:steps],
            **changes,
        },
    )

    (replay,) = replay_episodes([forged])

    assert replay.mismatch is not None and message in replay.mismatch
