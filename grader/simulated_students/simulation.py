"""In-process stand-in for the sandbox: run student-like functions on gymnasium and build CallRecords.

Calibration (bench/calibrate.py) and the checks' tests use it to judge thousands of regrades without
starting processes. Episodes are logged with the fields and seeds the sandbox's recorder logs; their
replays are either recomputed for real with `grader.sandbox.replay.replay_episode` or taken from the
trajectory as played (identical for unmodified gymnasium, and twice as fast).

With ``fast=True`` gymnasium's Blackjack draws its cards with Python's `random.Random.choice` instead of
numpy's `Generator.choice` (same uniform draw from the same 13-card deck, 20 times faster): the game
code is gymnasium's, only the random stream differs, so such episodes are judged as played.
"""

from __future__ import annotations

import copy
import inspect
import operator
import random
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import gymnasium
import numpy as np

from grader.compat import resolve_env_id
from grader.compat.events import ENV_OBJECT_PASSED
from grader.lab.checks.base import CallRecord
from grader.sandbox.child.envs import cheaper
from grader.sandbox.child.episode_fields import EPISODE_COLUMNS, EPISODE_FIELDS
from grader.sandbox.child.frames import ENV_NAME_OR_OBJECT, ENV_OBJECT, EnvArgument
from grader.sandbox.child.seeding import SeedStream, Stream, space_seed
from grader.sandbox.episode_log import EpisodeLog
from grader.sandbox.outcome import (
    Call,
    CallOutcome,
    CompatEventRecord,
    FunctionInfo,
    OutcomeStatus,
    ParameterInfo,
)
from grader.sandbox.replay import Replay, replay_episode

StudentFunction = Callable[..., Any]
"""A simulated student function: called as ``function(lab, *call.args, **call.kwargs)``."""


class _FastCards:
    """Stands in for Blackjack's numpy generator: only `choice` is used by gymnasium's Blackjack."""

    def __init__(self, seed: int) -> None:
        self._random = random.Random(seed)

    def choice(self, deck: Sequence[int]) -> int:
        return self._random.choice(deck)


@dataclass
class _Episode:
    played: EpisodeLog
    """The wire's fields (`EpisodeLog`), its columns appended to as the episode runs."""
    observations: list[Any]
    ended: bool = False

    def log(self) -> EpisodeLog:
        """The episode as the parent decodes it: every wire field (`EPISODE_FIELDS`), containers copied."""
        return EpisodeLog(**{name: copy.copy(getattr(self.played, name)) for name in EPISODE_FIELDS})

    def replay_as_played(self) -> Replay:
        played = self.played
        flags = map(operator.or_, played.terminated, played.truncated)
        ends = [step for step, end in enumerate(flags) if end]
        finished = bool(ends)
        length = ends[0] + 1 if finished else played.steps
        return Replay(
            observations=self.observations,
            rewards=played.rewards,
            terminated=played.terminated,
            truncated=played.truncated,
            length=length,
            finished=finished,
            steps_after_done=played.steps - length if finished else 0,
            mismatch=None,
            env_spec=None,
        )


class LabEnv:
    """A gymnasium env (5-tuple API) that logs its episodes like the sandbox's recorder."""

    def __init__(self, lab: Lab, requested_id: str, kwargs: dict[str, Any]) -> None:
        target = resolve_env_id(requested_id)
        self._lab = lab
        self._requested_id = requested_id
        self._env_id = target.gymnasium_id
        self._kwargs = target.merged_kwargs(kwargs)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            self._env = gymnasium.make(self._env_id, disable_env_checker=True, **self._kwargs)
        cheaper(self._env.unwrapped)  # the game as the sandbox child deals it: same steps, same draws
        self._index = len(lab.envs)
        lab.envs.append(self)
        self.action_space = self._env.action_space
        self.action_space.seed(space_seed(lab.call_seed, self._index))
        self.observation_space = self._env.observation_space
        self._episode: _Episode | None = None
        self._fast = lab.fast and self._env_id.startswith("Blackjack")
        if self._fast:
            self._env.reset(seed=0)
            self._env.unwrapped._np_random = _FastCards(lab.call_seed)  # type: ignore[attr-defined,assignment]

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        """Start a new episode; a student seed is mapped like the sandbox maps it; options are logged."""
        reset_seed = self._lab.reset_seed(seed)
        if self._fast:
            observation, info = self._env.reset()
        else:
            observation, info = self._env.reset(seed=reset_seed, options=options)
        header = (self._index, self._requested_id, self._env_id, dict(self._kwargs), reset_seed, seed)
        columns: dict[str, Any] = {name: [] for name in EPISODE_COLUMNS}
        played = EpisodeLog(*header, **columns, reset_options=options)
        self._episode = _Episode(played, [observation])
        self._lab.episodes.append(self._episode)
        return observation, info

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Step the env and log the step (steps after the end are logged too)."""
        if self._episode is None:
            raise RuntimeError("reset() before step()")
        episode, played = self._episode, self._episode.played
        if played.terminated and (played.terminated[-1] or played.truncated[-1] or episode.ended):
            episode.ended = True
            with warnings.catch_warnings():  # gymnasium warns about stepping after the end; the log says it
                warnings.simplefilter("ignore")
                observation, reward, terminated, truncated, info = self._env.step(action)
        else:
            observation, reward, terminated, truncated, info = self._env.step(action)
        episode.observations.append(observation)
        played.actions.append(action if not isinstance(action, np.integer) else int(action))
        played.rewards.append(float(reward))
        played.terminated.append(bool(terminated))
        played.truncated.append(bool(truncated))
        return observation, float(reward), bool(terminated), bool(truncated), info


class Lab:
    """What a simulated student function works with: ``make`` and randomness seeded by the call."""

    def __init__(self, call_seed: int, *, fast: bool = False) -> None:
        self.fast = fast
        self.random = random.Random(call_seed)
        self._resets = SeedStream(call_seed, Stream.RESETS)
        self.call_seed = call_seed
        self.envs: list[LabEnv] = []
        self.episodes: list[_Episode] = []
        self.named_envs: dict[str, int | None] = {}
        self.made_by_name = False

    def make(self, env_id: str, **kwargs: Any) -> LabEnv:
        """Make a logged env; the lab's ids resolve as in the sandbox (`Taxi-v2` raises). An id the call
        passed by name gets the argument's time limit unless one is given, as the sandbox's recorder does."""
        if isinstance(env_id, str) and env_id in self.named_envs:
            self.made_by_name = True
            if kwargs.get("max_episode_steps") is None:
                kwargs = {**kwargs, "max_episode_steps": self.named_envs[env_id]}
        return LabEnv(self, env_id, kwargs)

    def passed(self, argument: Any, *, as_objects: bool) -> Any:
        """What a function receives for a call's argument, as in the sandbox child: an `EnvArgument` as
        its name (noted, so an env made by it gets its limit) or as an env made here."""
        if type(argument) is not EnvArgument:
            return argument
        if argument.form != ENV_OBJECT and not as_objects:
            self.named_envs[argument.env_id] = argument.max_episode_steps
            return argument.env_id
        return self.make(argument.env_id, max_episode_steps=argument.max_episode_steps)

    def reset_seed(self, student_seed: int | None) -> int:
        """The seed a reset uses: the next grader seed (a student's seed is replaced, as in the sandbox)."""
        return self._resets.next()


def simulate_call(
    call: Call, function: StudentFunction, call_seed: int, *, replay: bool = False, fast: bool = False
) -> CallRecord:
    """Run one simulated call and build its record as the sandbox and the replay would.

    Args:
        call: The call the check planned.
        function: The simulated student function.
        call_seed: The call's seed (episodes and the student's randomness derive from it).
        replay: Replay every episode for real (True) or take the played trajectory as its replay.
        fast: Draw Blackjack cards with Python's generator (see the module docstring); implies no replay.
    """
    if fast and replay:
        raise ValueError(
            "fast Blackjack episodes cannot be replayed from their seeds; use fast=False to replay"
        )
    lab = Lab(call_seed, fast=fast)
    events: list[CompatEventRecord] = []
    started = time.perf_counter()
    try:
        value = _called(function, lab, call, as_objects=False)
    except Exception as error:
        replaceable = any(
            type(argument) is EnvArgument and argument.form == ENV_NAME_OR_OBJECT
            for argument in (*call.args, *dict(call.kwargs).values())
        )
        failure: Exception | None = error
        value = None
        if replaceable and not (lab.made_by_name or lab.episodes):  # as the child: again with objects
            lab = Lab(call_seed, fast=fast)
            try:
                value = _called(function, lab, call, as_objects=True)
                failure = None
            except Exception as again:
                failure = again if lab.episodes else error
            if failure is not error:
                events.append(
                    CompatEventRecord(
                        kind=ENV_OBJECT_PASSED,
                        env_id=next(a.env_id for a in call.args if type(a) is EnvArgument),
                        detail=f"{call.function}() raised {type(error).__name__}: {error} on the name",
                    )
                )
        if failure is not None:
            outcome = CallOutcome(
                call,
                OutcomeStatus.EXCEPTION,
                None,
                [],
                events,
                "",
                "",
                f"{call.function}() raised {type(failure).__name__}: {failure}",
                time.perf_counter() - started,
                call_seed,
            )
            return CallRecord(outcome, [])
    wall_time = time.perf_counter() - started
    episodes = lab.episodes if call.record_episodes else []
    logs = [episode.log() for episode in episodes]
    outcome = CallOutcome(call, OutcomeStatus.OK, value, logs, events, "", "", "", wall_time, call_seed)
    replays = (
        [replay_episode(log) for log in logs]
        if replay
        else [episode.replay_as_played() for episode in episodes]
    )
    return CallRecord(outcome, replays)


def _called(function: StudentFunction, lab: Lab, call: Call, *, as_objects: bool) -> Any:
    args = [lab.passed(argument, as_objects=as_objects) for argument in call.args]
    kwargs = {key: lab.passed(argument, as_objects=as_objects) for key, argument in dict(call.kwargs).items()}
    return function(lab, *args, **kwargs)


def simulate_calls(
    calls: Sequence[Call],
    functions: dict[str, StudentFunction],
    seed: int,
    *,
    replay: bool = False,
    fast: bool = False,
) -> list[CallRecord]:
    """Run planned calls against simulated functions; a function not in `functions` is missing.

    Args:
        calls: The planned calls.
        functions: Simulated student functions by name.
        seed: The regrade's seed; call k uses a seed derived from (seed, k).
        replay: See `simulate_call`.
        fast: See `simulate_call`.
    """
    records = []
    for index, call in enumerate(calls):
        call_seed = int(np.random.SeedSequence(seed, spawn_key=(index,)).generate_state(1, np.uint64)[0] >> 1)
        function = functions.get(call.function)
        if function is None:
            outcome = CallOutcome(
                call,
                OutcomeStatus.MISSING_FUNCTION,
                None,
                [],
                [],
                "",
                "",
                f"your file defines no function named `{call.function}`",
                0.0,
                call_seed,
            )
            records.append(CallRecord(outcome, []))
        else:
            records.append(simulate_call(call, function, call_seed, replay=replay, fast=fast))
    return records


def function_infos(functions: dict[str, StudentFunction]) -> dict[str, FunctionInfo]:
    """What the sandbox's `ready` frame would say about simulated functions (the `lab` parameter hidden)."""
    infos = {}
    for name, function in functions.items():
        parameters = list(inspect.signature(function).parameters.values())[1:]
        infos[name] = FunctionInfo(
            name,
            True,
            tuple(
                ParameterInfo(p.name, p.kind.name, p.default is not inspect.Parameter.empty)
                for p in parameters
            ),
        )
    return infos
