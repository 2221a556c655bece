"""Tests for the second lab's helper module (grader/compat/shim/model_free_RL.py, model_free_rl/)."""

from __future__ import annotations

from pathlib import Path

from ..conftest import RunScript


def test_the_helper_trains_into_the_working_directory(run_through_layer: RunScript, tmp_path: Path) -> None:
    result = run_through_layer(
        """
        import random
        import gymnasium as gym
        import numpy as np
        import model_free_RL
        import model_free_rl

        random.seed(7)
        model_free_RL.run_qlearn("FrozenLake-v1", N=300, decay=True)
        first = np.load("q_table.npy")
        random.seed(7)
        model_free_rl.run_q_learn("FrozenLake-v1", N=300, decay=True)
        env = gym.make("FrozenLake-v1", map_name="8x8", is_slippery=True)
        total = model_free_RL.run_simulation_table(env)
        print(first.shape, np.array_equal(first, np.load("q_table.npy")), 0.0 <= total <= 1.0,
              model_free_rl.run_q_learn is model_free_RL.run_qlearn)
        """
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[0] == "(64, 4) True True True"
    assert (tmp_path / "q_table.npy").is_file()


def test_epsilon_decay(run_through_layer: RunScript) -> None:
    result = run_through_layer(
        """
        from model_free_RL import epsilon_decay
        print(epsilon_decay(1, 10), round(epsilon_decay(10, 10, 1.0, 0.0), 12))
        exponential = epsilon_decay(10, 10, 1.0, 0.01, "exp"), epsilon_decay(5, 10, 1.0, 0.01, "EXP")
        print(*(round(value, 12) for value in exponential))
        try:
            epsilon_decay(1, 10, decay_type="cosine")
        except ValueError as error:
            print(error)
        """
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[:3] == [
        "1.0 0.1",
        "0.01 0.1",
        "decay_type is 'linear' or 'exp' (exponential), not 'cosine'",
    ]
