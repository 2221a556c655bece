"""Tests for grader.compat.make: classic gym.make on gymnasium, looked up at call time, quietly."""

from __future__ import annotations

import sys
import warnings
from typing import Any

import gymnasium
import pytest

from grader.compat import ClassicEnv, events, make


@pytest.fixture(autouse=True)
def _empty_log() -> None:
    events.drain()


def test_calls_gymnasium_make_at_call_time_with_the_resolved_id_and_merged_kwargs(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    calls: list[tuple[str, dict[str, Any]]] = []
    real_make = gymnasium.make

    def recording_make(env_id: str, **kwargs: Any) -> gymnasium.Env[Any, Any]:
        calls.append((env_id, kwargs))
        return real_make(env_id, **kwargs)

    monkeypatch.setattr(gymnasium, "make", recording_make)
    env = make("Blackjack-v0", natural=True)
    assert calls == [("Blackjack-v1", {"natural": True, "sab": False})]
    assert isinstance(env, ClassicEnv)
    assert (env.unwrapped.natural, env.unwrapped.sab) == (True, False)


def test_a_renamed_id_is_recorded_with_what_was_made() -> None:
    make("Blackjack-v0")
    make("CartPole-v0")
    assert [(event.kind, event.env_id) for event in events.drain()] == [(events.RENAMED_ID, "Blackjack-v0")]


def test_renamed_event_names_the_gymnasium_call() -> None:
    make("Taxi-v3")
    (event,) = events.drain()
    assert event.detail.startswith("Taxi-v3 was made as gymnasium.make('Taxi-v4'): ")


def test_old_versions_the_lab_uses_make_no_gymnasium_deprecation_noise() -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        make("CartPole-v0")
    assert [str(warning.message) for warning in caught] == []


def test_lab_envs_are_registered_on_first_make() -> None:
    env = make("NChain-v0")
    assert env.spec is not None and env.spec.max_episode_steps == 1000


def test_gymnasium_make_is_called_directly_from_make_with_the_requested_id_in_env_id(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The sandbox's recorder reads the requested id from this frame; see grader/sandbox/child/recorder.py."""
    callers: list[tuple[object, object]] = []
    real_make = gymnasium.make

    def recording_make(env_id: str, **kwargs: Any) -> gymnasium.Env[Any, Any]:
        caller = sys._getframe(1)
        callers.append((caller.f_code, caller.f_locals.get("env_id")))
        return real_make(env_id, **kwargs)

    monkeypatch.setattr(gymnasium, "make", recording_make)
    make("Taxi-v3")
    assert callers == [(make.__code__, "Taxi-v3")]
