"""Replay many CartPole episodes at once: gymnasium's CartPole step, written over arrays.

Stepping gymnasium's scalar CartPole costs as much as the student's own run, so replaying episodes
one by one cannot cost a small fraction of it. Here every episode advances in one array operation
per step: the same float64 expressions as `CartPoleEnv.step`, in the same order, with the constants
read from the parent's own gymnasium env. Initial states come from that env's own `reset(seed)`.
The result is bit-identical to the scalar env (checked in `tests/grader/sandbox/test_replay.py`,
and at run time by `grader.sandbox.replay`, which replays the longest episode of every batch with
the scalar env and discards the batch if they differ). Episodes that disagree with the log are
replayed again by the scalar env, which stays the authority for every mismatch.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium
import numpy as np
from gymnasium.envs.classic_control.cartpole import CartPoleEnv

from grader.sandbox.batched.replayer import BatchedEpisode, int_actions, lockstep, plain_arguments
from grader.sandbox.episode_log import EpisodeLog

ENV_IDS = frozenset({"CartPole-v0", "CartPole-v1"})


class CartPoleReplayer:
    """`BatchedReplayer` for `CartPole-v0`/`-v1` with default arguments (optionally `max_episode_steps`)."""

    def is_batchable(self, log: EpisodeLog) -> bool:
        """Plain CartPole arguments, no reset options, actions 0 or 1."""
        return plain_arguments(log, ENV_IDS) and int_actions(log.actions, 2)

    def replay(self, logs: Sequence[EpisodeLog]) -> list[BatchedEpisode]:
        """Replay CartPole logs sharing `env_id` and `env_kwargs` in lockstep."""
        return lockstep(logs, CartPoleEnv, _advance)


def _advance(
    scalar: gymnasium.Env[Any, Any], cartpole: CartPoleEnv, logs: Sequence[EpisodeLog], actions: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    initial = np.empty((4, len(logs)))
    for column, log in enumerate(logs):
        scalar.reset(seed=log.reset_seed)
        initial[:, column] = cartpole.state
    observations, terminated = _run(cartpole, initial, actions)
    return observations, np.ones(terminated.shape), terminated


def _run(env: CartPoleEnv, initial: np.ndarray, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`CartPoleEnv.step` over arrays: returns float32 observations and the terminated flags.

    Up to and including its last step an episode earns 1.0 per step (the default reward;
    `sutton_barto_reward` is not batchable), so rewards are not computed here.
    """
    steps, count = actions.shape
    states = np.empty((steps + 1, 4, count))
    states[0] = initial
    x, x_dot, theta, theta_dot = initial.copy()
    forces = np.where(actions == 1, env.force_mag, -env.force_mag)
    gravity, length, masspole, total_mass = env.gravity, env.length, env.masspole, env.total_mass
    polemass_length, tau, euler = env.polemass_length, env.tau, env.kinematics_integrator == "euler"
    for step in range(steps):
        costheta = np.cos(theta)
        sintheta = np.sin(theta)
        temp = (forces[step] + polemass_length * np.square(theta_dot) * sintheta) / total_mass
        thetaacc = (gravity * sintheta - costheta * temp) / (
            length * (4.0 / 3.0 - masspole * np.square(costheta) / total_mass)
        )
        xacc = temp - polemass_length * thetaacc * costheta / total_mass
        if euler:
            x = x + tau * x_dot
            x_dot = x_dot + tau * xacc
            theta = theta + tau * theta_dot
            theta_dot = theta_dot + tau * thetaacc
        else:
            x_dot = x_dot + tau * xacc
            x = x + tau * x_dot
            theta_dot = theta_dot + tau * thetaacc
            theta = theta + tau * theta_dot
        states[step + 1, 0], states[step + 1, 1], states[step + 1, 2], states[step + 1, 3] = (
            x,
            x_dot,
            theta,
            theta_dot,
        )
    positions, angles = states[1:, 0], states[1:, 2]
    terminated = (
        (positions < -env.x_threshold)
        | (positions > env.x_threshold)
        | (angles < -env.theta_threshold_radians)
        | (angles > env.theta_threshold_radians)
    )
    return states.transpose(0, 2, 1).astype(np.float32), terminated
