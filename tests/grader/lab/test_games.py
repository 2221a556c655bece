"""The games each problem accepts (its declaration's `games`): ids, rule arguments, restriction."""

from __future__ import annotations

import pytest

from grader.lab.games import BLACKJACK_V1, CARTPOLE_V0, allowed_games, game_names
from grader.lab.problems import problem as declared
from grader.sandbox.episode_log import EpisodeLog


def _log(env_id: str, requested_id: str, **kwargs: object) -> EpisodeLog:
    return EpisodeLog(
        env_index=0,
        requested_id=requested_id,
        env_id=env_id,
        env_kwargs=dict(kwargs),
        reset_seed=1,
        student_seed=None,
        actions=[0],
        rewards=[0.0],
        terminated=[True],
        truncated=[False],
    )


CASES = [
    ("blackjack-v0", "blackjack", None, _log("Blackjack-v1", "Blackjack-v0", natural=False, sab=False), None),
    ("blackjack-v1-sab", "blackjack", None, _log("Blackjack-v1", "Blackjack-v1"), None),
    (
        "blackjack-natural",
        "random_blackjack",
        None,
        _log("Blackjack-v1", "Blackjack-v0", sab=False, natural=True),
        None,
    ),
    (
        "blackjack-v1-restricted",
        "blackjack",
        ["Blackjack-v0"],
        _log("Blackjack-v1", "Blackjack-v1"),
        "Blackjack-v0 is played with sab=False, but your environment had sab=True, which changes the game: "
        "this assignment accepts Blackjack-v0; make the environment with gym.make('Blackjack-v0') and no "
        "extra arguments",
    ),
    ("cartpole-v1", "cartpole", None, _log("CartPole-v1", "CartPole-v1"), None),
    (
        "cartpole-v1-restricted",
        "cartpole",
        ["CartPole-v0"],
        _log("CartPole-v1", "CartPole-v1"),
        "the episodes must be played in CartPole-v0, but you made 'CartPole-v1' (gymnasium CartPole-v1), a "
        "different game: use gym.make('CartPole-v0')",
    ),
    (
        "time-limit-override",
        "cartpole",
        None,
        _log("CartPole-v0", "CartPole-v0", max_episode_steps=500),
        "you made 'CartPole-v0' with max_episode_steps=500, which changes the game: this assignment accepts "
        "CartPole-v0 or CartPole-v1; make the environment with gym.make('CartPole-v0') and no extra "
        "arguments",
    ),
    ("render-mode", "cartpole", None, _log("CartPole-v0", "CartPole-v0", render_mode="human"), None),
    ("taxi", "taxi", None, _log("Taxi-v4", "Taxi-v3"), None),
    (
        "rainy-taxi",
        "taxi",
        None,
        _log("Taxi-v4", "Taxi-v3", is_rainy=True),
        "Taxi-v3 is played with is_rainy=False, but your environment had is_rainy=True, which changes the "
        "game: this assignment accepts Taxi-v3; make the environment with gym.make('Taxi-v3') and no extra "
        "arguments",
    ),
]


@pytest.mark.parametrize(
    ("problem", "restrict", "log", "expected"), [case[1:] for case in CASES], ids=[case[0] for case in CASES]
)
def test_accepted_games(
    problem: str, restrict: list[str] | None, log: EpisodeLog, expected: str | None
) -> None:
    assert allowed_games(declared(problem).games, restrict, problem=problem).problem_with(log) == expected  # type: ignore[arg-type]


def test_the_game_played_is_identified_and_mixing_games_is_named() -> None:
    rules = allowed_games(declared("blackjack").games)
    assert rules.played_game([_log("Blackjack-v1", "Blackjack-v1")]) is BLACKJACK_V1
    assert rules.played_game([]).name == "Blackjack-v0"
    mixed = rules.played_game(
        [_log("Blackjack-v1", "Blackjack-v1"), _log("Blackjack-v1", "Blackjack-v0", sab=False)]
    )
    assert isinstance(mixed, str) and mixed.startswith("your episodes were played in Blackjack-v1 (Sutton")
    assert (
        allowed_games(declared("cartpole").games).played_game([_log("CartPole-v0", "CartPole-v0")])
        is CARTPOLE_V0
    )


def test_a_restriction_names_only_accepted_games() -> None:
    assert game_names(declared("cartpole").games) == ("CartPole-v0", "CartPole-v1")
    with pytest.raises(ValueError, match="cartpole accepts the games CartPole-v0, CartPole-v1; found"):
        allowed_games(declared("cartpole").games, ["CartPole-v2"], problem="cartpole")


def test_a_problem_that_declares_no_games_has_no_rules() -> None:
    assert declared("find_qvalues").games == ()
    with pytest.raises(ValueError, match="find_qvalues declares no games"):
        allowed_games(declared("find_qvalues").games, problem="find_qvalues")
