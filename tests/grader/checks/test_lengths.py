"""cartpole and car: the lab's bars, stated with what was measured.

False-fail probability of the passing tests: see bench/RESULTS.md (## Calibration), below 1e-6.
"""

from grader.checks.behaviours import _episode_length

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
