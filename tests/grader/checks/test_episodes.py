"""Integrity diagnoses shared by every check: the lab's game, altered logs, unfinished and repeated games."""

import dataclasses

from grader.checks import CHECKS
from grader.checks.base import CallRecord
from grader.checks.behaviours import cartpole, velocity_policy
from grader.checks.episodes import integrity_problem, played_episodes
from grader.games import allowed_games
from grader.sandbox.replay import replay_episode

from .support import grade, simulate, small_config


def _tampered(records: list[CallRecord], **changes: object) -> list[CallRecord]:
    first = records[0]
    log = dataclasses.replace(first.outcome.episodes[0], **changes)
    episodes = [log, *first.outcome.episodes[1:]]
    outcome = dataclasses.replace(first.outcome, episodes=episodes)
    return [CallRecord(outcome, [replay_episode(log), *first.replays[1:]]), *records[1:]]


def test_a_forged_reward_does_not_replay(seed: int) -> None:
    records = simulate("cartpole", {"cartpole": cartpole}, seed)
    forged = _tampered(records, rewards=[2.0] * len(records[0].outcome.episodes[0].rewards))
    problem = integrity_problem(forged, played_episodes(forged), allowed_games("cartpole"))
    assert problem is not None and problem.startswith(
        "episode 1 of call 1 did not replay: step 1 of the episode"
    )


def test_a_chosen_reset_seed_is_caught(seed: int) -> None:
    records = simulate("cartpole", {"cartpole": cartpole}, seed)
    forged = _tampered(records, reset_seed=12345)
    problem = integrity_problem(forged, played_episodes(forged), allowed_games("cartpole"))
    assert problem is not None and "the episode log was altered" in problem


def test_resetting_in_the_middle_of_a_game_fails(seed: int) -> None:
    def random_blackjack(lab, n):  # type: ignore[no-untyped-def]
        env = lab.make("Blackjack-v0")
        wins = 0
        for _ in range(n):
            env.reset()
            _, reward, _, _, _ = env.step(1)  # one card, then on to the next game
            wins += reward > 0
        return wins / n

    verdict = grade("random_blackjack", {"random_blackjack": random_blackjack}, seed)
    assert verdict.status == "failed"
    assert "abandoned before they ended" in verdict.feedback
    assert "you reset (or stopped) in the middle of a game" in verdict.feedback


def test_repeated_seeds_within_a_call_are_not_independent(seed: int) -> None:
    def random_blackjack(lab, n):  # type: ignore[no-untyped-def]
        env = lab.make("Blackjack-v0")
        wins = 0
        for _ in range(n):
            env.reset(seed=7)
            done = False
            while not done:
                _, reward, terminated, truncated, _ = env.step(int(env.action_space.sample()))
                done = terminated or truncated
            wins += reward > 0
        return wins / n

    verdict = grade("random_blackjack", {"random_blackjack": random_blackjack}, seed)
    assert verdict.status == "failed"
    assert "2000 episodes were reset with the same seed (7)" in verdict.feedback


def test_two_episodes_in_one_cartpole_call_fail(seed: int) -> None:
    def twice(lab):  # type: ignore[no-untyped-def]
        cartpole(lab)
        return cartpole(lab)

    verdict = grade("cartpole", {"cartpole": twice}, seed, small_config("cartpole", calls=3))
    assert verdict.status == "failed"
    assert verdict.feedback.startswith(
        "each call of cartpole() must play exactly one episode and return its length; call 1 played 2."
    )


def test_plans_name_the_functions() -> None:
    calls = CHECKS["cartpole"].plan(small_config("cartpole"), {})
    assert [call.function for call in calls] == ["cartpole"] * 100
    assert velocity_policy([0, 0, 0, 0.1]) == 1
