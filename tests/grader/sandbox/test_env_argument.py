"""An `EnvArgument` in a call's arguments reaches the student's function as an env the recorder logs."""

from __future__ import annotations

import json
import textwrap
from pathlib import Path
from typing import Any

import pytest

from grader.sandbox import Call, CallBudget, Limits, OutcomeStatus, Sandbox
from grader.sandbox.child.errors import InvalidValueError
from grader.sandbox.child.frames import EnvArgument, decode_value, encode_value

LIMITS = Limits(call_seconds=20, import_seconds=20, output_bytes=1024, frame_bytes=1 << 20)
LEARNER = textwrap.dedent("""
    def learner(env, steps):
        state, _ = env.reset()
        for _ in range(steps):
            env.step(0)
        return [env.spec.id, env.spec.max_episode_steps, int(env.observation_space.n)]
""")


def test_the_child_makes_the_env_and_records_its_episodes(tmp_path: Path) -> None:
    submission = tmp_path / "learner.py"
    submission.write_text(LEARNER, encoding="utf-8")
    call = Call("learner", (EnvArgument("Taxi-v3", 1000), 3), budget=CallBudget(4, 100))
    with Sandbox(submission, seed=1, limits=LIMITS) as sandbox:
        outcome = sandbox.call(call)
    assert outcome.status is OutcomeStatus.OK, outcome.message
    assert outcome.value == ["Taxi-v4", 1000, 500]
    assert outcome.compat_events == []  # the grader named Taxi-v3, not the student: no renaming reported
    (episode,) = outcome.episodes
    assert len(episode.actions) == 3
    assert episode.env_kwargs["max_episode_steps"] == 1000


def test_an_env_argument_survives_the_wire_only_in_arguments() -> None:
    wire = json.loads(json.dumps(encode_value([EnvArgument("Taxi-v3", 7), 1])))
    assert decode_value(wire, allow_envs=True) == [EnvArgument("Taxi-v3", 7), 1]
    with pytest.raises(InvalidValueError, match="unknown tagged object"):
        decode_value(wire)


@pytest.mark.parametrize(
    "spec",
    [
        {"id": "Taxi-v3"},
        {"id": "", "max_episode_steps": None},
        {"id": "x" * 101, "max_episode_steps": None},
        {"id": "Taxi-v3", "max_episode_steps": 0},
        {"id": "Taxi-v3", "max_episode_steps": True},
        {"id": ["Taxi-v3"], "max_episode_steps": None},
    ],
    ids=["no-limit-field", "empty-id", "long-id", "zero-limit", "bool-limit", "list-id"],
)
def test_a_malformed_env_argument_is_refused(spec: Any) -> None:
    with pytest.raises(InvalidValueError):
        decode_value({"$env": spec}, allow_envs=True)
