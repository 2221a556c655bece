"""cartpole and car: the lab's bars, stated with what was measured.

False-fail probability of the passing tests: see bench/RESULTS.md (## Calibration), below 1e-6.
"""

from functools import partial

from grader.simulated_students.behaviours import _episode_length, _random_step_first, car_policy

from .support import grade, small_config


def test_pole_angle_policy_misses_the_cartpole_bar(seed: int) -> None:
    def angle(lab):  # type: ignore[no-untyped-def]
        return _episode_length(lab.make("CartPole-v0"), lambda observation: 1 if observation[2] > 0 else 0)

    verdict = grade("cartpole", {"cartpole": angle}, seed)
    assert verdict.status == "failed"
    assert "(graded: mean >= 170 and every run >= 120); your 100 replayed runs lasted" in verdict.feedback
    assert verdict.measurements["mean_steps"] < 60  # type: ignore[operator]


def test_slow_car_misses_the_mean_bar(seed: int) -> None:
    def slow(lab):  # type: ignore[no-untyped-def]
        return _episode_length(
            lab.make("MountainCar-v0"), lambda observation: 2 if observation[1] >= 0 else 0
        )

    verdict = grade("car", {"car": slow}, seed, small_config("car", calls=20, max_mean_steps=100.0))
    assert verdict.status == "failed"
    assert "fewer than 100 steps on average; 20 of your 20 replayed runs reached the flag" in verdict.feedback


def test_off_by_one_count_is_named(seed: int) -> None:
    def counted_reset(lab):  # type: ignore[no-untyped-def]
        return 1 + _episode_length(
            lab.make("MountainCar-v0"), lambda observation: 2 if observation[1] >= 0 else 0
        )

    verdict = grade("car", {"car": counted_reset}, seed, small_config("car", calls=2))
    assert verdict.status == "failed"
    assert "it is off by one" in verdict.feedback


def test_steps_before_the_counted_loop_are_a_note_with_the_configured_deduction(seed: int) -> None:
    functions = {"car": partial(_random_step_first, env_id="MountainCar-v0", policy=car_policy)}
    settings = small_config("car", calls=10, uncounted_steps_deduction=0.25)
    verdict = grade("car", functions, seed, settings)
    assert (verdict.status, verdict.fraction) == ("passed", 0.75)
    assert verdict.measurements["uncounted_steps"] == 1
    assert verdict.feedback.endswith(
        "Note: every count car() returned is one step short of its replayed episode: the step taken before "
        "the counted loop (e.g. a random step after reset) was not counted. The verdict follows the replayed "
        "episodes (25% of the points deducted); count every env.step() call."
    )


def test_counts_short_by_different_amounts_stay_a_failure(seed: int) -> None:
    calls = iter(range(10))

    def uneven(lab):  # type: ignore[no-untyped-def]
        return _episode_length(lab.make("MountainCar-v0"), car_policy) - next(calls) % 2

    verdict = grade("car", {"car": uneven}, seed, small_config("car", calls=4))
    assert verdict.status == "failed"
    assert "call 2 of car() returned" in verdict.feedback and "it is off by one" in verdict.feedback


def _car_length(lab):  # type: ignore[no-untyped-def]
    return _episode_length(lab.make("MountainCar-v0"), car_policy)


def test_a_count_that_is_no_number_is_named(seed: int) -> None:
    def says_it(lab):  # type: ignore[no-untyped-def]
        return f"{_car_length(lab)} steps"

    verdict = grade("car", {"car": says_it}, seed, small_config("car", calls=2))
    assert verdict.status == "failed"
    assert verdict.feedback.startswith("call 1 of car() returned '")
    assert verdict.feedback.endswith("steps (replayed); expected a number.")


def test_counts_short_by_more_than_a_slip_stay_a_failure(seed: int) -> None:
    """Every count short by the same 4 steps: more than the lab-era slip of steps before the counted loop."""

    def four_short(lab):  # type: ignore[no-untyped-def]
        return _car_length(lab) - 4

    verdict = grade("car", {"car": four_short}, seed, small_config("car", calls=3))
    assert verdict.status == "failed"
    assert "it is not the length of the episode the call played" in verdict.feedback


def test_episodes_of_two_versions_of_the_game_fail(seed: int) -> None:
    calls = iter(range(10))

    def alternating(lab):  # type: ignore[no-untyped-def]
        env_id = ("CartPole-v0", "CartPole-v1")[next(calls) % 2]
        return _episode_length(lab.make(env_id), lambda observation: 1 if observation[3] > 0 else 0)

    verdict = grade("cartpole", {"cartpole": alternating}, seed, small_config("cartpole", calls=2))
    assert verdict.status == "failed"
    assert "each problem is graded against one game's exact results" in verdict.feedback
