"""The lab text's own snippets (submissions/lab_snippets), run through the layer, show what the lab shows."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from .conftest import RunScript

SNIPPETS = Path(__file__).resolve().parents[3] / "submissions" / "lab_snippets"


def _snippet(name: str) -> str:
    return (SNIPPETS / name).read_text()


def _event_lines(stderr: str) -> list[str]:
    """The summary's event lines (after its "gymgrade compat:" header) reduced to "kind [env_id]", except
    the API detections (every snippet gets classic gym: `test_every_snippet_is_served_classic_gym`)."""
    summary = stderr[stderr.rindex("gymgrade compat:") :].splitlines()[1:]
    lines = [line.split(":")[0].strip() for line in summary]
    return [line for line in lines if not line.startswith("api_detected")]


def _detections(stderr: str) -> list[str]:
    summary = stderr[stderr.rindex("gymgrade compat:") :].splitlines()[1:]
    return [line.strip() for line in summary if line.strip().startswith("api_detected")]


@pytest.mark.parametrize(
    "name",
    sorted(path.name for path in SNIPPETS.glob("*.py") if path.name != "find_qvalues.py"),
)
def test_every_snippet_is_served_classic_gym(run_through_layer: RunScript, name: str) -> None:
    result = run_through_layer(_snippet(name))
    detections = _detections(result.stderr)
    assert detections, result.stderr
    assert all("classic gym API" in line for line in detections), detections


def test_registry_listing_and_nchain_reset(run_through_layer: RunScript) -> None:
    result = run_through_layer(_snippet("environments.py"))
    assert result.returncode == 0, result.stderr
    listing, reset = result.stdout.splitlines()
    assert listing.startswith("dict_values([EnvSpec(id='")
    assert "id='NChain-v0'" in listing
    assert reset == "0"
    assert _event_lines(result.stderr) == []


def test_action_spaces_and_a_random_step(run_through_layer: RunScript) -> None:
    result = run_through_layer(_snippet("action_space.py"))
    assert result.returncode == 0, result.stderr
    space, step, shape, high, low = result.stdout.splitlines()
    assert space == "Discrete(2)"
    observation, reward, done, info = ast.literal_eval(step)
    assert (observation in (0, 1), reward in (0, 2), done, info) == (True, True, False, {})
    assert (shape, high, low) == ("(1,)", "array([10000.], dtype=float32)", "array([-10000.], dtype=float32)")


def test_a_random_guess_returns_observation_reward_done_info(run_through_layer: RunScript) -> None:
    result = run_through_layer(_snippet("observation_space.py"))
    assert result.returncode == 0, result.stderr
    observation, reward, done, info = ast.literal_eval(result.stdout.strip())
    assert (observation in (1, 3), reward in (0, 1), done == bool(reward)) == (True, True, True)
    assert list(info) == ["guesses", "number"] and info["guesses"] == 1
    assert -1000 <= info["number"] < 1000
    assert _event_lines(result.stderr) == []


def test_acrobot_render_loop_runs_headless_and_ends(run_through_layer: RunScript) -> None:
    result = run_through_layer(_snippet("acrobot_render.py"))
    assert result.returncode == 0, result.stderr
    assert result.stdout == "done True\n"
    assert _event_lines(result.stderr) == ["render_without_mode [Acrobot-v1]", "numpy_action [Acrobot-v1]"]


@pytest.mark.slow  # trains a Q-table, seconds
def test_find_qvalues_as_printed_in_the_lab_trains_a_taxi_table(run_through_layer: RunScript) -> None:
    code = _snippet("find_qvalues.py")
    assert "range(1,100001)" in code
    result = run_through_layer(code.replace("range(1,100001)", "range(1,301)"))
    assert result.returncode == 0, result.stderr
    lines = [line.replace("\x1b[2K", "").strip() for line in result.stdout.splitlines()]
    assert [line for line in lines if line] == [
        "Episode: 100",
        "Episode: 200",
        "Episode: 300",
        "Training finished.",
        "(500, 6)",
    ]
    assert _event_lines(result.stderr) == ["renamed_id [Taxi-v3]", "numpy_action [Taxi-v3]"]


def test_blackjack_without_reset_plays_as_classic_gym_did(run_through_layer: RunScript) -> None:
    result = run_through_layer(_snippet("random_blackjack.py"), "200")
    assert result.returncode == 0, result.stderr
    assert 0 <= float(result.stdout) <= 1
    assert _event_lines(result.stderr) == [
        "renamed_id [Blackjack-v0]",
        "step_before_reset [Blackjack-v0]",
        "numpy_action [Blackjack-v0]",
    ]
    assert "step_before_reset [Blackjack-v0]: step() was called before reset(); " in result.stderr
    assert "(200 times)" in result.stderr


def test_classic_tolerances_through_the_gym_module(run_through_layer: RunScript) -> None:
    result = run_through_layer(
        """
        import warnings
        import gym
        import numpy as np
        env = gym.make("CartPole-v0")
        env.step(np.int64(0))
        done = False
        while not done:
            _, _, done, _ = env.step(0)
        _, _, done, _ = env.step(0)
        warnings.warn("the student's own warning")
        print(done)
        """
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout == "True\n"
    assert "UserWarning: the student's own warning" in result.stderr
    assert "out of date" not in result.stderr and "already returned terminated" not in result.stderr
    assert _event_lines(result.stderr) == [
        "step_before_reset [CartPole-v0]",
        "numpy_action [CartPole-v0]",
        "step_after_done [CartPole-v0]",
    ]


def test_a_retired_id_names_the_lab_id(run_through_layer: RunScript) -> None:
    result = run_through_layer(
        """
        import gym
        try:
            gym.make("Taxi-v2")
        except gym.error.Error as error:
            print(error)
        """
    )
    assert result.stdout == (
        "gym.make('Taxi-v2'): Taxi-v2 was retired before this lab; the lab uses Taxi-v3. "
        "Write gym.make('Taxi-v3').\n"
    )


@pytest.mark.slow  # runs the whole lab solution
def test_the_classic_complete_sample_submission_runs_through_the_layer(run_through_layer: RunScript) -> None:
    """Its functions on small inputs (running the whole file takes minutes: 100 000 Q-learning episodes)."""
    submission = SNIPPETS.parent / "classic_complete.py"
    result = run_through_layer(
        f"""
        import runpy
        solution = runpy.run_path({str(submission)!r})
        steps = solution["cartpole"](), solution["car"]()
        rates = solution["random_blackjack"](50), solution["blackjack"](11)
        print(all(1 <= count <= 200 for count in steps), all(0 <= rate <= 1 for rate in rates))
        """
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout == "True True\n"
    assert _event_lines(result.stderr) == ["renamed_id [Blackjack-v0]", "numpy_action [Blackjack-v0]"]
