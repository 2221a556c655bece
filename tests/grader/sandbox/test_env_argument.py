"""An `EnvArgument` in a call's arguments reaches the student's function as an env the recorder logs, or as
the environment's name, the env made by it recorded (`name`), the name first and an object after a failure
on the name (`name_or_object`)."""

from __future__ import annotations

import json
import textwrap
from pathlib import Path
from typing import Any

import pytest

from grader.sandbox import Call, CallBudget, Limits, OutcomeStatus, Sandbox
from grader.sandbox.child.errors import InvalidValueError
from grader.sandbox.child.frames import (
    ENV_NAME,
    ENV_NAME_OR_OBJECT,
    EnvArgument,
    decode_value,
    encode_value,
)

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


TEMPLATE_SHAPED = textwrap.dedent("""
    import gymnasium as gym

    def learner(env, steps):
        name = env
        env = gym.make(env)
        state, _ = env.reset()
        for _ in range(steps):
            env.step(0)
        return [name, env.spec.max_episode_steps]

    def broken(env, steps):
        raise ValueError("before anything")

    def broken_after_make(env, steps):
        env = gym.make(env)
        raise ValueError("after gym.make")
""")


def _outcome(tmp_path: Path, source: str, function: str, form: str) -> Any:
    submission = tmp_path / "learner.py"
    submission.write_text(source, encoding="utf-8")
    call = Call(function, (EnvArgument("Taxi-v3", 1000, form), 3), budget=CallBudget(4, 100))
    with Sandbox(submission, seed=1, limits=LIMITS) as sandbox:
        return sandbox.call(call)


@pytest.mark.parametrize("form", [ENV_NAME, ENV_NAME_OR_OBJECT])
def test_the_name_reaches_the_function_and_the_env_it_makes_is_recorded(tmp_path: Path, form: str) -> None:
    outcome = _outcome(tmp_path, TEMPLATE_SHAPED, "learner", form)
    assert outcome.status is OutcomeStatus.OK, outcome.message
    assert outcome.value == ["Taxi-v3", 1000]  # the name; the env made by it has the argument's limit
    assert outcome.compat_events == []  # the grader named Taxi-v3: no renaming reported
    (episode,) = outcome.episodes
    assert (episode.requested_id, episode.env_id, len(episode.actions)) == ("Taxi-v3", "Taxi-v4", 3)
    assert episode.env_kwargs["max_episode_steps"] == 1000


def test_a_function_that_fails_on_the_name_gets_an_env_object(tmp_path: Path) -> None:
    outcome = _outcome(tmp_path, LEARNER, "learner", ENV_NAME_OR_OBJECT)
    assert outcome.status is OutcomeStatus.OK, outcome.message
    assert outcome.value == ["Taxi-v4", 1000, 500]
    (event,) = outcome.compat_events
    assert (event.kind, event.env_id) == ("env_object", "Taxi-v3")
    assert "raised AttributeError" in event.detail
    assert len(outcome.episodes) == 1


@pytest.mark.parametrize(
    ("function", "error"),
    [("broken", "before anything"), ("broken_after_make", "after gym.make")],
    ids=["fails-with-the-object-too", "made-the-env-by-name"],
)
def test_the_names_error_stands_when_the_object_gets_no_further(
    tmp_path: Path, function: str, error: str
) -> None:
    outcome = _outcome(tmp_path, TEMPLATE_SHAPED, function, ENV_NAME_OR_OBJECT)
    assert outcome.status is OutcomeStatus.EXCEPTION
    assert f"ValueError: {error}" in outcome.message
    assert outcome.compat_events == []


def test_a_name_only_argument_is_never_replaced(tmp_path: Path) -> None:
    outcome = _outcome(tmp_path, LEARNER, "learner", ENV_NAME)
    assert outcome.status is OutcomeStatus.EXCEPTION
    assert "'str' object has no attribute" in outcome.message


def test_an_env_argument_survives_the_wire_only_in_arguments() -> None:
    wire = json.loads(
        json.dumps(encode_value([EnvArgument("Taxi-v3", 7), EnvArgument("Taxi-v3", 7, ENV_NAME), 1]))
    )
    assert decode_value(wire, allow_envs=True) == [
        EnvArgument("Taxi-v3", 7),
        EnvArgument("Taxi-v3", 7, ENV_NAME),
        1,
    ]
    with pytest.raises(InvalidValueError, match="unknown tagged object"):
        decode_value(wire)


@pytest.mark.parametrize(
    "spec",
    [
        {"id": "Taxi-v3", "form": "object"},
        {"id": "Taxi-v3", "max_episode_steps": None},
        {"id": "", "max_episode_steps": None, "form": "object"},
        {"id": "x" * 101, "max_episode_steps": None, "form": "object"},
        {"id": "Taxi-v3", "max_episode_steps": 0, "form": "object"},
        {"id": "Taxi-v3", "max_episode_steps": True, "form": "object"},
        {"id": ["Taxi-v3"], "max_episode_steps": None, "form": "object"},
        {"id": "Taxi-v3", "max_episode_steps": None, "form": "anything"},
        {"id": "Taxi-v3", "max_episode_steps": None, "form": 1},
    ],
    ids=[
        "no-limit-field",
        "no-form-field",
        "empty-id",
        "long-id",
        "zero-limit",
        "bool-limit",
        "list-id",
        "unknown-form",
        "int-form",
    ],
)
def test_a_malformed_env_argument_is_refused(spec: Any) -> None:
    with pytest.raises(InvalidValueError):
        decode_value({"$env": spec}, allow_envs=True)
