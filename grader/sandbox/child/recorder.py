"""The episode recorder: wraps every env `gymnasium.make` returns and owns the call's randomness.

`install` replaces `gymnasium.make` (all three names it is bound to), `numpy.random.default_rng`
and `gymnasium.utils.seeding.np_random` so that unseeded randomness comes from the call's seed
streams. An env that is one of gymnasium's lab games is dealt by its cheaper twin (`envs.cheaper`:
the same game, the same draws, fewer numpy calls per step). The recorder sits outermost on each env,
sees the gymnasium-API `reset`/`step` (the compat `gym` shim wraps it in turn), reseeds every reset
from the grader's stream and logs actions and what the made env reported. The chain below it is served to
student code as levels that step through it (`gym.make(id).env`, `env.env.env`:
`grader.compat.chain`), so an episode played on any of them is recorded too. The parent replays the logs
(`grader.sandbox.replay`); nothing here is trusted.
"""

from __future__ import annotations

import contextlib
import sys
import weakref
from array import array
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from types import FrameType
from typing import Any

import gymnasium
import gymnasium.envs
import gymnasium.envs.registration
import gymnasium.spaces
import gymnasium.utils.seeding
import numpy as np

from grader.compat import events as compat_events
from grader.compat import make as compat_make
from grader.compat import register_envs, resolve_env_id
from grader.compat.chain import served_levels
from grader.sandbox.child import envs
from grader.sandbox.child.budget import WireBudget
from grader.sandbox.child.episode_fields import EPISODE_FIELDS, EpisodeHeader, check_declaration
from grader.sandbox.child.seeding import CallSeeds, kept_generator_seed

DEFAULT_MAX_RECORDED_STEPS = 5_000_000
MAX_KEPT_GENERATORS = 10_000
"""Generators made at import that are reset at every call (strong references, so capped)."""
_DROPPED_KWARGS = ("render_mode", "disable_env_checker")
_COMPAT_MAKE_CODE = compat_make.__code__
_NO_STEP_LIMIT = sys.maxsize
_FLOAT_ERRORS = (TypeError, ValueError, OverflowError)


@dataclass(frozen=True)
class EpisodeRecord(EpisodeHeader):
    """One episode as the student played it (child-side; its columns grow while the episode runs).

    Its first fields are the wire's (`episode_fields.EPISODE_FIELDS`, checked at import). The columns are
    compact typed arrays, appended to without creating a Python object per step: actions as 64-bit ints
    (a list from the first action that is not a plain int, a `Box` env's arrays say), rewards as doubles,
    the flags as bytes. `grader.sandbox.child.log_block` joins a call's episodes into one block for the
    wire. Frozen as its header is; `actions` becoming a list is set through `_replace_field`.
    """

    reset_options: dict[str, Any] | None
    actions: array[int] | list[Any] = field(default_factory=lambda: array("q"))
    rewards: array[float] = field(default_factory=lambda: array("d"))
    terminated: bytearray = field(default_factory=bytearray)
    truncated: bytearray = field(default_factory=bytearray)

    def add_action(self, action: Any) -> None:
        """Log one action (a copy: the student may mutate an array they passed), the general case.

        `RecordingEnv.step` appends a plain int itself; anything else comes here, and the column becomes
        a list the first time an action is not an int that fits 64 bits.
        """
        copied = _copy_action(action)
        actions = self.actions
        if type(actions) is array:
            if type(copied) is int:
                with contextlib.suppress(OverflowError):
                    actions.append(copied)
                    return
            actions = list(actions)
            self._replace_field("actions", actions)
        actions.append(copied)

    def _replace_field(self, name: str, value: Any) -> None:
        object.__setattr__(self, name, value)  # the frozen header's dataclass forbids plain assignment


check_declaration(
    tuple(item.name for item in fields(EpisodeRecord))[: len(EPISODE_FIELDS)], "recorder.EpisodeRecord"
)


@dataclass(frozen=True)
class MadeEnv:
    """How an env was made: what the student asked for and what rebuilds it with `gymnasium.make`."""

    requested_id: str
    env_id: str
    env_kwargs: dict[str, Any]


class Recorder:
    """Per-process recording state; `begin_call` starts a call, `finish_call` returns its episodes.

    While a call records, every reset and every step of its envs is counted against the call's
    budget (`resets`, `steps`), whether or not it is logged; once either count exceeds the budget,
    `exceeded` names it and nothing more is logged.
    """

    def __init__(self, seed: int, max_recorded_steps: int = DEFAULT_MAX_RECORDED_STEPS) -> None:
        self.seeds = CallSeeds(seed)
        self.max_recorded_steps = max_recorded_steps
        self.recording = False
        self.overflowed = False
        self.record_call = False
        self.budget: WireBudget | None = None
        self.step_limit = _NO_STEP_LIMIT
        """The call's `max_steps` (read on every step), unlimited without a budget."""
        self.resets = 0
        self.steps = 0
        self.played = 0
        """Resets of the call followed by at least one step (the games it played), counted like `resets`."""
        self.exceeded: str | None = None
        """"episodes" or "steps" once the call went beyond its budget."""
        self.episodes: list[EpisodeRecord] = []
        self._recorded_steps = 0
        self._live_envs: list[weakref.ref[RecordingEnv]] = []
        self._env_numbers = 0
        self._call_indices: dict[int, int] = {}
        self._generators: list[tuple[np.random.Generator, Mapping[str, Any] | None]] = []
        self.importing = False
        self.named_envs: dict[str, int | None] = {}
        """Ids the grader passed by name to the call (lab id and gymnasium id) -> the time limit an env
        made by that name gets when the function names none (`EnvArgument` of form name)."""
        self.made_by_name = False
        """Whether the call made an env by one of `named_envs`' ids."""

    def begin_import(self, import_seed: int) -> None:
        """Seed the import of the submission; generators made until `finish_import` are kept."""
        self.begin_call(import_seed, record=False)
        self.importing = True

    def finish_import(self, module_globals: Mapping[str, Any]) -> None:
        """Give the spaces the module defines their generators now, so that they are kept too."""
        for value in list(module_globals.values()):
            if gymnasium.spaces.Space in type(value).__mro__:
                with contextlib.suppress(Exception):
                    value.np_random  # noqa: B018 (the property creates the space's generator)
        self.importing = False
        self.finish_call()

    def begin_call(self, call_seed: int, *, record: bool, budget: WireBudget | None = None) -> None:
        """Reseed everything from `call_seed` and start an empty episode log (limited by `budget`)."""
        self.importing = False
        self.seeds = CallSeeds(call_seed)
        self.recording = record
        self.record_call = record
        self.budget = budget
        self.step_limit = _NO_STEP_LIMIT if budget is None else budget.max_steps
        self.resets = 0
        self.steps = 0
        self.played = 0
        self.exceeded = None
        self.overflowed = False
        self.episodes = []
        self.named_envs = {}
        self.made_by_name = False
        self._recorded_steps = 0
        self._call_indices = {}
        self._live_envs = [ref for ref in self._live_envs if ref() is not None]
        self._env_numbers = 0
        for ref in self._live_envs:
            env = ref()
            if env is not None:
                self.seed_spaces(env)
        for number, (generator, initial_state) in enumerate(self._generators):
            bit_generator = generator.bit_generator
            if initial_state is None:
                bit_generator.state = type(bit_generator)(kept_generator_seed(call_seed, number)).state
            else:
                bit_generator.state = initial_state

    def finish_call(self) -> list[EpisodeRecord]:
        """Stop recording and return the call's episodes in reset order (for `log_block.log_block`)."""
        self.recording = False
        self.record_call = False
        episodes, self.episodes = self.episodes, []
        return episodes

    def keep_generator(self, generator: np.random.Generator, *, seeded: bool) -> None:
        """While importing: reset `generator` at every call (to its first state if seeded, else reseeded).

        A generator in a module global would otherwise carry one call's randomness into the next, and
        a restarted child (fresh import) would give different results. Generators made during calls
        are not kept: they take their seeds from the call's own streams.
        """
        if self.importing and len(self._generators) < MAX_KEPT_GENERATORS:
            self._generators.append((generator, generator.bit_generator.state if seeded else None))

    def register(self, env: RecordingEnv) -> None:
        """Track a new env so its spaces are reseeded at every call."""
        self._live_envs.append(weakref.ref(env))
        self.seed_spaces(env)

    def seed_spaces(self, env: RecordingEnv) -> None:
        """Seed the env's action and observation spaces from the call's space stream."""
        number = self._env_numbers
        self._env_numbers += 1
        env.action_space.seed(self.seeds.space_seed(2 * number))
        env.observation_space.seed(self.seeds.space_seed(2 * number + 1))

    def count_reset(self) -> None:
        """Count one reset of an env against the call's budget (every reset, logged or not)."""
        if not self.record_call:
            return
        self.resets += 1
        if self.budget is not None and self.resets > self.budget.max_episodes:
            self.exceed("episodes")

    def start_episode(
        self, env: RecordingEnv, reset_seed: int, student_seed: int | None, options: dict[str, Any] | None
    ) -> EpisodeRecord | None:
        """Count the reset and open a new episode for `env`; None when not recording."""
        self.count_reset()
        if not self.recording or not self._spend_step():
            return None
        index = self._call_indices.setdefault(id(env), len(self._call_indices))
        made = env.made
        episode = EpisodeRecord(
            index, made.requested_id, made.env_id, made.env_kwargs, reset_seed, student_seed, options
        )
        self.episodes.append(episode)
        return episode

    def exceed(self, what: str) -> None:
        """The call went beyond its budget (`what`: "episodes" or "steps"): log nothing more, send nothing."""
        if self.exceeded is None:
            self.exceeded = what
        self.recording = False
        self.episodes = []  # never sent: the call ends with episode_limit

    def _spend_step(self) -> bool:
        if self._recorded_steps >= self.max_recorded_steps:
            self.overflowed = True
            self.recording = False
            return False
        self._recorded_steps += 1
        return True


class RecordingEnv(gymnasium.Wrapper[Any, Any, Any, Any]):
    """The outermost wrapper of every env made in the child: grader-seeded resets, logged steps.

    It stands for the env `gymnasium.make` made (`served`, gym.make's `TimeLimit`) and steps it; its `env`
    is the next level of that chain as student code sees it (`grader.compat.chain.served_levels`:
    `gym.make(id).env` without the time limit, then `env.env`, down to the raw env),
    each stepping through this wrapper, so every episode is recorded whichever level is played. The log's
    flags are always the made env's (its time limit's truncation included); a level below the limit only
    hides it from the student, and the replay continues such an episode past the limit
    (`grader.sandbox.replay.replay_past_time_limit`).
    """

    def __init__(self, env: gymnasium.Env[Any, Any], recorder: Recorder, made: MadeEnv) -> None:
        super().__init__(env)  # `Wrapper.__init__`'s `self.env = env` sets `served` (the property's setter)
        self.recorder = recorder
        self.made = made
        self._episode: EpisodeRecord | None = None
        self._fresh = False
        self.passed_by_grader = False
        """Set by the child for an env it made for an `EnvArgument` (`grader.sandbox.child.calls`)."""

    @property
    def env(self) -> gymnasium.Env[Any, Any]:
        """The next level of the made env's chain as student code sees it, made at each read.

        Made anew rather than kept: the levels hold this wrapper (their stepper), and a kept level would
        make a reference cycle that outlives the student's last reference until the garbage collector runs,
        so that an env dropped in one call would still be reseeded, and counted, in the next.
        """
        return served_levels(self.served, self)

    @env.setter
    def env(self, made: gymnasium.Env[Any, Any]) -> None:
        self.served = made

    @property
    def unwrapped(self) -> gymnasium.Env[Any, Any]:
        """Gymnasium's raw env, as everywhere."""
        return self.served.unwrapped

    @property  # type: ignore[misc]
    def action_space(self) -> Any:  # type: ignore[override]
        """The made env's action space."""
        return self.served.action_space

    @property  # type: ignore[misc]
    def observation_space(self) -> Any:  # type: ignore[override]
        """The made env's observation space."""
        return self.served.observation_space

    @property  # type: ignore[misc]
    def metadata(self) -> Any:  # type: ignore[override]
        """The made env's metadata."""
        return self.served.metadata

    @property
    def render_mode(self) -> Any:  # type: ignore[override]
        """The made env's render mode."""
        return self.served.render_mode

    @property
    def np_random(self) -> Any:
        """The made env's random generator."""
        return self.served.np_random

    @np_random.setter
    def np_random(self, generator: Any) -> None:
        self.served.np_random = generator

    @staticmethod
    def served_of(level: RecordingEnv) -> gymnasium.Env[Any, Any]:
        """The env `gymnasium.make` made, which `level` stands for (`grader.compat.chain.real_env`)."""
        return level.served

    @property
    def spec(self) -> Any:  # type: ignore[override]
        """The made env's spec."""
        return self.served.spec

    def render(self) -> Any:
        """Render as the made env does."""
        return self.served.render()

    def __str__(self) -> str:
        return f"<RecordingEnv{self.served}>"

    def __getattr__(self, name: str) -> Any:
        """Read a public attribute of the wrapped envs (`env.P`, `env.nrow`), as gym and gymnasium before
        1.0 forwarded it and the second lab's texts (`dictionary_P = env.P`) expect; a compat event says so.

        Only reads reach here (names this wrapper lacks); private names are refused as gymnasium refuses
        them. Nothing new is exposed: `env.unwrapped` gives the same objects.
        """
        env = self.__dict__.get("served")
        if name.startswith("_"):
            raise AttributeError(f"accessing private attribute {name!r} of a gym environment is prohibited")
        if env is None:
            raise AttributeError(name)
        value = env.get_wrapper_attr(name)
        made = self.__dict__.get("made")
        compat_events.record(
            compat_events.WRAPPER_ATTRIBUTE,
            f"{made.requested_id if made is not None else 'env'}: env.{name}",
            f"env.{name} was read through gymnasium's wrappers, which gymnasium 1.x no longer forwards; "
            f"the grader forwarded it (env.unwrapped.{name} works everywhere)",
        )
        return value

    def close(self) -> None:
        """Close the env; closing one the grader passed to the call is noted as a compat event (`env_closed`):
        the second lab's `run_simulation` is told not to close the env it is given."""
        if self.__dict__.get("passed_by_grader"):
            compat_events.record(
                compat_events.ENV_CLOSED,
                self.made.requested_id,
                "env.close() was called on the environment the grader passed",
            )
        self.served.close()

    def reset(self, *, seed: Any = None, options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        """Reset with the next seed of the grader's stream, whatever seed the student passed.

        A student's seed cannot choose the start (it could be searched for an easy one): it is replaced,
        noted as a compat event, and logged as `student_seed` when it is a plain non-negative int (the
        checks diagnose a seed repeated over games, which outside the grader replays the same game).
        """
        self._episode = None
        actual_seed = self.recorder.seeds.next_reset_seed()
        student_seed = _plain_seed(seed)
        if seed is not None:
            shown = repr(seed) if type(seed) in (int, bool, float) else f"of type {type(seed).__name__}"
            compat_events.record(
                compat_events.SEED_REPLACED,
                self.made.requested_id,
                f"reset(seed=...) with your seed {shown[:40]} was given the grader's next seed instead: "
                "the grader deals every start, so results do not depend on seeds you choose",
            )
        result = self.served.reset(seed=actual_seed, options=options)
        logged_options = dict(options) if type(options) is dict else options
        self._episode = self.recorder.start_episode(self, actual_seed, student_seed, logged_options)
        self._fresh = True
        return result

    def step(self, action: Any) -> tuple[Any, Any, bool, bool, dict[str, Any]]:
        """Step the env, count the step against the call's budget and log the action and what the student saw.

        The recorder's per-step work, in this one frame (it runs millions of times a call: Taxi plays 2
        million steps): every step of a recording call counts (`steps`, and `played` for the first step
        after a reset); while the call records, the step is appended to the open episode's typed columns
        until `max_recorded_steps` (then `overflowed`). A reward that is not a number is logged as NaN
        (the replay then reports the mismatch).
        """
        result = self.served.step(action)
        recorder = self.recorder
        if recorder.record_call:
            if self._fresh:
                self._fresh = False
                recorder.played += 1
            steps = recorder.steps = recorder.steps + 1
            if steps > recorder.step_limit:
                recorder.exceed("steps")
            episode = self._episode
            if episode is not None and recorder.recording:
                if recorder._recorded_steps >= recorder.max_recorded_steps:
                    recorder.overflowed = True
                    recorder.recording = False
                    return result
                recorder._recorded_steps += 1
                if type(action) is int and type(episode.actions) is array:
                    try:
                        episode.actions.append(action)
                    except OverflowError:
                        episode.add_action(action)
                else:
                    episode.add_action(action)
                reward, terminated, truncated = result[1], result[2], result[3]
                try:
                    episode.rewards.append(reward)  # type: ignore[arg-type]  # converted by array, or refused
                except _FLOAT_ERRORS:
                    episode.rewards.append(_float_or_nan(reward))
                episode.terminated.append(terminated if type(terminated) is bool else bool(terminated))
                episode.truncated.append(truncated if type(truncated) is bool else bool(truncated))
        elif self._fresh:
            self._fresh = False
        return result


def install(recorder: Recorder) -> None:
    """Route env creation and unseeded randomness of this process through `recorder`."""
    original_make = gymnasium.envs.registration.make

    def make(
        id: Any, max_episode_steps: int | None = None, disable_env_checker: bool | None = None, **kwargs: Any
    ) -> gymnasium.Env[Any, Any]:
        if kwargs.get("render_mode") == "human":
            kwargs["render_mode"] = None
        requested = id
        named = isinstance(id, str) and id in recorder.named_envs
        if isinstance(id, str) and ":" not in id and id not in gymnasium.envs.registration.registry:
            id, kwargs = _resolve_lab_id(id, kwargs, quiet=named)
        if isinstance(id, str) and id in recorder.named_envs:  # the name the grader passed (or its target)
            recorder.made_by_name = True
            if max_episode_steps is None:
                max_episode_steps = recorder.named_envs[id]
        env = original_make(id, max_episode_steps, disable_env_checker, **kwargs)
        envs.cheaper(env.unwrapped)
        made = describe_make(id, max_episode_steps, kwargs, sys._getframe(1), env.unwrapped.spec)
        if requested is not id:
            made = MadeEnv(requested, made.env_id, made.env_kwargs)
        recording_env = RecordingEnv(env, recorder, made)
        recorder.register(recording_env)
        return recording_env

    make.__doc__ = original_make.__doc__
    gymnasium.make = make
    gymnasium.envs.make = make
    gymnasium.envs.registration.make = make
    _route_unseeded_generators(recorder)


def _resolve_lab_id(
    requested: str, kwargs: dict[str, Any], *, quiet: bool = False
) -> tuple[str, dict[str, Any]]:
    """Make a lab id gymnasium no longer registers (`Taxi-v3`) work through plain `gymnasium.make` too.

    Gymnasium-API submissions keep the lab's ids (the grader itself calls `find_qvalues("Taxi-v3")` and
    `sarsa0("Taxi-v3", ...)`); they are resolved exactly as the compat `gym.make` resolves them, and the
    renaming is reported unless `quiet` (the grader passed that name). An id the lab never used still fails,
    with the compat layer's message naming the lab's id.
    """
    target = resolve_env_id(requested)
    register_envs()
    merged = target.merged_kwargs(kwargs)
    if quiet:
        return target.gymnasium_id, merged
    arguments = "".join(f", {name}={value!r}" for name, value in target.kwargs.items())
    compat_events.record(
        compat_events.RENAMED_ID,
        requested,
        f"gymnasium.make({requested!r}) was made as gymnasium.make({target.gymnasium_id!r}{arguments}): "
        f"{target.note}",
    )
    return target.gymnasium_id, merged


def describe_make(
    id: Any,
    max_episode_steps: int | None,
    kwargs: dict[str, Any],
    caller: FrameType | None,
    made_spec: gymnasium.envs.registration.EnvSpec | None = None,
) -> MadeEnv:
    """What to log for a `gymnasium.make(id, max_episode_steps, **kwargs)` call made from `caller`.

    `made_spec` is the spec gymnasium gave the new env; its id is the registered id even when the
    student wrote `"module:Env-v0"`.
    """
    env_kwargs = {key: value for key, value in kwargs.items() if key not in _DROPPED_KWARGS}
    if isinstance(id, gymnasium.envs.registration.EnvSpec):
        env_id = id.id
        env_kwargs = {
            key: value for key, value in id.kwargs.items() if key not in _DROPPED_KWARGS
        } | env_kwargs
        registered = gymnasium.envs.registration.registry.get(env_id)
        if (
            max_episode_steps is None
            and registered is not None
            and id.max_episode_steps != registered.max_episode_steps
        ):
            max_episode_steps = -1 if id.max_episode_steps is None else id.max_episode_steps
    else:
        env_id = made_spec.id if made_spec is not None else str(id)
    if max_episode_steps is not None:
        env_kwargs["max_episode_steps"] = max_episode_steps
    return MadeEnv(_requested_id(caller, env_id), env_id, env_kwargs)


def _requested_id(caller: FrameType | None, made_id: str) -> str:
    """The id the student passed to the compat `gym.make`, else the id given to `gymnasium.make`.

    `grader.compat.make(env_id, **kwargs)` resolves the classic id and calls `gymnasium.make` with
    the gymnasium id; when that function is our direct caller, its `env_id` is the requested id.
    """
    if caller is not None and caller.f_code is _COMPAT_MAKE_CODE:
        requested = caller.f_locals.get("env_id")
        if isinstance(requested, str):
            return requested
    return made_id


def _route_unseeded_generators(recorder: Recorder) -> None:
    original_np_random = gymnasium.utils.seeding.np_random
    original_default_rng = np.random.default_rng

    def np_random(seed: int | None = None) -> tuple[np.random.Generator, int]:
        if seed is not None:
            return original_np_random(seed)
        generator, entropy = original_np_random(recorder.seeds.next_unseeded_generator_seed())
        recorder.keep_generator(generator, seeded=False)
        return generator, entropy

    def default_rng(seed: Any = None) -> np.random.Generator:
        unseeded = seed is None
        generator = original_default_rng(recorder.seeds.next_default_rng_seed() if unseeded else seed)
        if generator is not seed:
            recorder.keep_generator(generator, seeded=not unseeded)
        return generator

    np_random.__doc__ = original_np_random.__doc__
    default_rng.__doc__ = original_default_rng.__doc__
    gymnasium.utils.seeding.np_random = np_random
    np.random.default_rng = default_rng


def _plain_seed(seed: Any) -> int | None:
    """The student's seed as logged: a plain non-negative int below 2**64, else None."""
    if isinstance(seed, int | np.integer) and not isinstance(seed, bool | np.bool_) and 0 <= seed < 2**64:
        return int(seed)
    return None


def _float_or_nan(reward: Any) -> float:
    """`float(reward)`, or NaN for what is not a number (a string `float` parses is a number here too)."""
    try:
        return float(reward)
    except _FLOAT_ERRORS:
        return float("nan")


def _copy_action(action: Any) -> Any:
    kind = type(action)
    if kind is int or kind is float or kind is bool:
        return action
    if isinstance(action, np.integer):
        return int(action)
    if isinstance(action, np.floating):
        return float(action)
    if isinstance(action, np.ndarray):
        return np.array(action)  # a copy, and a plain ndarray even for a subclass
    if kind is list or kind is tuple:
        return [_copy_action(item) for item in action]
    return action
