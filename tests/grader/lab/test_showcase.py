"""Which episode the report animates: the worst of the lab's own games, and only one the replay confirmed."""

from __future__ import annotations

from typing import Any

import pytest

from grader.lab.checks.base import CallRecord
from grader.lab.problems import problem
from grader.lab.showcase import showcase_episode
from grader.sandbox import Call, CallOutcome, EpisodeLog, OutcomeStatus
from grader.sandbox.replay import Replay


def _episode(
    length: int, *, env_id: str = "CartPole-v0", seed: int = 0, **changes: Any
) -> tuple[EpisodeLog, Replay]:
    log = EpisodeLog(
        env_index=0, requested_id=env_id, env_id=env_id, env_kwargs=changes.get("env_kwargs", {}),
        reset_seed=seed, student_seed=None, actions=[1] * length, rewards=[1.0] * length,
        terminated=[False] * (length - 1) + [True], truncated=[False] * length,
        reset_options=changes.get("reset_options"),
    )  # fmt: skip
    replay = Replay(
        observations=[], rewards=[1.0] * length, terminated=log.terminated, truncated=log.truncated,
        length=length, finished=True, steps_after_done=0, mismatch=changes.get("mismatch"), env_spec=None,
    )  # fmt: skip
    return log, replay


def _records(
    *episodes: tuple[EpisodeLog, Replay], status: OutcomeStatus = OutcomeStatus.OK
) -> list[CallRecord]:
    return [
        CallRecord(
            CallOutcome(call=Call("cartpole"), status=status, value=None, episodes=[log], compat_events=[],
                        stdout="", stderr="", message="", wall_time=0.0, seed=0),
            [replay],
        )
        for log, replay in episodes
    ]  # fmt: skip


def test_cartpole_shows_the_shortest_episode() -> None:
    chosen = showcase_episode(
        problem("cartpole").showcase, _records(_episode(150, seed=1), _episode(90, seed=2), _episode(200))
    )
    assert chosen is not None
    assert (chosen.reset_seed, chosen.length, chosen.label) == (2, 90, "your shortest of 3 CartPole episodes")


def test_mountain_car_shows_the_longest_episode() -> None:
    episodes = [
        _episode(120, env_id="MountainCar-v0", seed=1),
        _episode(140, env_id="MountainCar-v0", seed=2),
    ]
    chosen = showcase_episode(problem("car").showcase, _records(*episodes))
    assert chosen is not None and (chosen.reset_seed, chosen.length) == (2, 140)


@pytest.mark.parametrize(
    "changes",
    [{"mismatch": "step 3: reward differs"}, {"env_kwargs": {"gravity": 0.1}}, {"reset_options": {"low": 0}},
     {"env_id": "Acrobot-v1"}],
    ids=["replay-disagrees", "student-kwargs", "reset-options", "another-game"],
)  # fmt: skip
def test_only_episodes_the_grader_can_vouch_for_are_shown(changes: dict[str, Any]) -> None:
    assert showcase_episode(problem("cartpole").showcase, _records(_episode(10, **changes))) is None


def test_problems_without_a_game_to_show_have_no_replay() -> None:
    assert (
        showcase_episode(problem("blackjack").showcase, _records(_episode(3, env_id="Blackjack-v1"))) is None
    )
