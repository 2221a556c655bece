"""Tests for grader.compat.ids: lab ids resolve to the same game in gymnasium 1.4, others fail clearly."""

from __future__ import annotations

from typing import Any

import gymnasium
import pytest

from grader.compat import RetiredEnvironmentError, UnknownEnvironmentError, resolve_env_id
from grader.compat.ids import lab_ids

RESOLVED = [
    ("Blackjack-v0", "Blackjack-v1", {"natural": False, "sab": False}),
    ("Taxi-v3", "Taxi-v4", {}),
    ("CartPole-v0", "CartPole-v0", {}),
    ("CartPole-v1", "CartPole-v1", {}),
    ("MountainCar-v0", "MountainCar-v0", {}),
    ("MountainCarContinuous-v0", "MountainCarContinuous-v0", {}),
    ("Acrobot-v1", "Acrobot-v1", {}),
    ("Pendulum-v0", "Pendulum-v1", {}),
    ("FrozenLake-v0", "FrozenLake-v1", {}),
    ("FrozenLake8x8-v0", "FrozenLake8x8-v1", {}),
    ("NChain-v0", "NChain-v0", {}),
    ("GuessingGame-v0", "GuessingGame-v0", {}),
    ("Blackjack-v1", "Blackjack-v1", {}),
    ("Taxi-v4", "Taxi-v4", {}),
    ("LunarLander-v3", "LunarLander-v3", {}),
]


@pytest.mark.parametrize(("env_id", "gymnasium_id", "kwargs"), RESOLVED, ids=[row[0] for row in RESOLVED])
def test_resolves_to_the_same_game(env_id: str, gymnasium_id: str, kwargs: dict[str, Any]) -> None:
    target = resolve_env_id(env_id)
    assert (target.gymnasium_id, target.kwargs) == (gymnasium_id, kwargs)


@pytest.mark.parametrize("env_id", [row[0] for row in RESOLVED if row[0] != row[1]])
def test_renamed_ids_say_why(env_id: str) -> None:
    assert resolve_env_id(env_id).note


@pytest.mark.parametrize("env_id", [row[0] for row in RESOLVED if row[0] == row[1]])
def test_unchanged_ids_have_no_note(env_id: str) -> None:
    assert resolve_env_id(env_id).note == ""


def test_every_target_is_registered_once_the_layer_registered_its_envs() -> None:
    from grader.compat import register_envs

    register_envs()
    missing = [
        env_id for env_id in lab_ids() if resolve_env_id(env_id).gymnasium_id not in gymnasium.envs.registry
    ]
    assert missing == []


FAILURES = [
    (
        "Taxi-v2",
        RetiredEnvironmentError,
        "gym.make('Taxi-v2'): Taxi-v2 was retired before this lab; the lab uses Taxi-v3. "
        "Write gym.make('Taxi-v3').",
    ),
    (
        "Taxi-v1",
        RetiredEnvironmentError,
        "gym.make('Taxi-v1'): Taxi-v1 was retired before this lab; the lab uses Taxi-v3. "
        "Write gym.make('Taxi-v3').",
    ),
    (
        "Blackjack-v2",
        RetiredEnvironmentError,
        "gym.make('Blackjack-v2'): Blackjack-v2 never existed; the lab uses Blackjack-v0. "
        "Write gym.make('Blackjack-v0').",
    ),
    (
        "CartPole-v2",
        RetiredEnvironmentError,
        "gym.make('CartPole-v2'): CartPole-v2 never existed; the lab uses CartPole-v0. "
        "Write gym.make('CartPole-v0').",
    ),
    (
        "Taxi",
        RetiredEnvironmentError,
        "gym.make('Taxi'): Taxi has no version; the lab uses Taxi-v3. Write gym.make('Taxi-v3').",
    ),
    (
        "Blackjak-v0",
        UnknownEnvironmentError,
        "gym.make('Blackjak-v0'): no environment of this lab or of gymnasium 1.4.0 is called 'Blackjak-v0'. "
        "Did you mean 'Blackjack-v0' or 'Blackjack-v1'?",
    ),
    (
        "taxi-v3",
        UnknownEnvironmentError,
        "gym.make('taxi-v3'): no environment of this lab or of gymnasium 1.4.0 is called 'taxi-v3'. "
        "Did you mean 'Taxi-v3'?",
    ),
    (
        "GuesingGame-v0",
        UnknownEnvironmentError,
        "gym.make('GuesingGame-v0'): no environment of this lab or of gymnasium 1.4.0 is called "
        "'GuesingGame-v0'. Did you mean 'GuessingGame-v0'?",
    ),
    (
        "Copy-v0",
        UnknownEnvironmentError,
        "gym.make('Copy-v0'): no environment of this lab or of gymnasium 1.4.0 is called 'Copy-v0'. "
        "The lab uses Blackjack-v0, Taxi-v3, CartPole-v0, MountainCar-v0, Acrobot-v1, NChain-v0, "
        "GuessingGame-v0.",
    ),
    (
        "LunarLander-v2",
        RetiredEnvironmentError,
        "gym.make('LunarLander-v2'): LunarLander-v2 is not available in gymnasium 1.4.0, which has "
        "LunarLander-v3. The lab does not use this game; if you need it, read the documentation of "
        "LunarLander-v3 first: its rules may differ from LunarLander-v2's.",
    ),
]


@pytest.mark.parametrize(("env_id", "error", "message"), FAILURES, ids=[row[0] for row in FAILURES])
def test_unusable_ids_fail_with_a_message_naming_the_lab_id(
    env_id: str, error: type[Exception], message: str
) -> None:
    with pytest.raises(error) as raised:
        resolve_env_id(env_id)
    assert str(raised.value) == message


def test_errors_are_gym_errors_for_classic_code_that_catches_them() -> None:
    with pytest.raises(gymnasium.error.Error):
        resolve_env_id("Taxi-v2")


def test_a_non_string_id_is_refused_with_what_to_do() -> None:
    with pytest.raises(UnknownEnvironmentError, match=r"expects an environment id string such as 'Taxi-v3'"):
        resolve_env_id(3)  # type: ignore[arg-type]


def test_student_kwargs_win_over_the_target_kwargs() -> None:
    target = resolve_env_id("Blackjack-v0")
    assert target.merged_kwargs({"sab": True, "render_mode": "rgb_array"}) == {
        "natural": False,
        "sab": True,
        "render_mode": "rgb_array",
    }


def test_each_call_returns_its_own_kwargs() -> None:
    resolve_env_id("Blackjack-v0").kwargs["sab"] = True
    assert resolve_env_id("Blackjack-v0").kwargs == {"natural": False, "sab": False}
