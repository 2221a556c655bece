"""`ClassicEnv`: a gymnasium environment seen through the classic gym API the lab was written for."""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.wrappers import TimeLimit

from . import events
from .chain import SERVED_CHAIN, limit_reached, time_limit_of
from .detection import Api
from .dialect import caller_api
from .errors import UnsupportedRenderModeError
from .quiet import STEP_AFTER_TERMINATED, quiet_gymnasium


class ClassicEnv:
    """`gym` behaviour on top of a gymnasium 1.4 environment: classic gym or gym 0.26, per call site.

    Each `reset()`/`step()` serves the API its calling code was written for (`grader.compat.dialect`;
    `api=` fixes one). Classic gym (0.17 to 0.25):

    - `reset()` returns the observation only (`return_info=True` gives `(obs, info)`);
    - `step(a)` returns `(obs, reward, done, info)` with `done = terminated or truncated`, and
      `info["TimeLimit.truncated"]` when the time limit ended the episode, as classic `TimeLimit` did;
    - `seed(s)` stores `s` for the next reset; `render()` draws nothing and returns None.

    gym 0.26: `reset()` returns `(obs, info)` and `step(a)` `(obs, reward, terminated, truncated, info)`,
    gymnasium's own API; everything else is shared.

    Where classic gym tolerated what gymnasium refuses, this class behaves as classic gym did and
    records a `CompatEvent` (see `grader.compat.events`): a step before the first reset resets first
    (classic Blackjack dealt its first hand in the constructor; classic envs with a time limit refused
    such a step, the layer resets them all alike and the event tells), a step after done is passed
    through to the env (gymnasium's envs and `TimeLimit` accept it, as classic ones did), numpy integer
    actions for a `Discrete` space become ints (gymnasium accepts them too; ints keep the logs plain).

    Attribute reads not defined here go down the gymnasium wrapper stack (`env.P`, `env.s`), as
    classic `gym.Wrapper.__getattr__` did; private names are not forwarded. `nS` and `nA`, which classic
    toy-text envs (FrozenLake, Taxi) had and gymnasium's do not, are the sizes of the discrete spaces.
    `env.env`, `env.env.env` and `env.env.env.env` are the levels of `gym.make`'s chain below the time limit
    (`grader.compat.chain.SERVED_CHAIN`, then the raw env, which has no `env`): views of the same env whose
    episodes end only when the env ends them, each stepping the one gymnasium env underneath
    (`gymnasium_env`), so a recorder sees every step whichever level is played.
    """

    def __init__(
        self,
        env: gymnasium.Env[Any, Any],
        requested_id: str,
        api: Api | None = None,
        *,
        level: int = 0,
    ) -> None:
        """Wrap `env`, which `gymnasium.make` created for the id `requested_id`.

        Args:
            env: the gymnasium environment.
            requested_id: the id the student asked for.
            api: serve this API to every caller; None decides per call site from the calling code.
            level: the level of `gym.make`'s chain served: 0 is the env `gym.make` returns (with its time
                limit), 1 `env.env` and so on (no time limit), `len(SERVED_CHAIN)` the raw env.
        """
        self.gymnasium_env = env
        self.requested_id = requested_id
        self.api = api
        self.level = level
        self.time_limit = level == 0
        self._inner_view: ClassicEnv | None = None
        self._discrete_actions = isinstance(env.action_space, spaces.Discrete)
        self._needs_reset = True
        self._done = False
        self._next_seed: int | None = None
        self._render_recorded = False

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None, return_info: bool = False
    ) -> Any:
        """Start an episode; return the first observation (classic), or `(obs, info)` (gym 0.26).

        Args:
            seed: seed for this reset; if None, the seed given to `seed()` since the last reset, if any.
            options: passed to the gymnasium reset.
            return_info: return `(obs, info)` as gym 0.22 to 0.25 did.

        Raises:
            AmbiguousApiError: the calling code expects both APIs (see `grader.compat.dialect`).
        """
        api = self.api or caller_api(self.requested_id)
        observation, info = self._reset(seed, options)
        return (observation, info) if return_info or api is Api.GYM026 else observation

    def _reset(self, seed: int | None, options: dict[str, Any] | None) -> tuple[Any, dict[str, Any]]:
        if seed is None:
            seed = self._next_seed
        self._next_seed = None
        observation, info = self.gymnasium_env.reset(seed=seed, options=options)
        self._needs_reset = False
        self._done = False
        return observation, info

    def step(self, action: Any) -> tuple[Any, ...]:
        """Take one step; return `(obs, reward, done, info)` or gym 0.26's 5 values (see the class docstring).

        Raises:
            AmbiguousApiError: the calling code expects both APIs (see `grader.compat.dialect`).
        """
        api = self.api or caller_api(self.requested_id)
        if self._needs_reset:
            events.record(
                events.STEP_BEFORE_RESET,
                self.requested_id,
                "step() was called before reset(); the layer reset the environment first, as classic Blackjack had dealt a hand in its constructor",  # noqa: E501
            )
            self._reset(None, None)
        if self._discrete_actions and type(action) is not int:
            action = self._plain_action(action)
        if self._done:
            events.record(
                events.STEP_AFTER_DONE,
                self.requested_id,
                "step() was called after the episode returned done=True and before reset(); "
                "the step was passed to the environment as classic gym did, so what followed is undefined",
            )
            with quiet_gymnasium(STEP_AFTER_TERMINATED):
                observation, reward, terminated, truncated, info = self.gymnasium_env.step(action)
        else:
            observation, reward, terminated, truncated, info = self.gymnasium_env.step(action)
        if truncated and not self.time_limit and self._cut_by_time_limit():
            truncated = False  # classic `env.env` had no time limit: the episode goes on
        if api is Api.GYM026:
            self._done = self._done or bool(terminated or truncated)
            return observation, reward, terminated, truncated, info
        if truncated:
            info = {**info, "TimeLimit.truncated": not terminated}
        done = bool(terminated or truncated)
        self._done = self._done or done
        return observation, reward, done, info

    def _plain_action(self, action: Any) -> Any:
        if isinstance(action, np.integer) or (
            isinstance(action, np.ndarray) and action.shape == () and np.issubdtype(action.dtype, np.integer)
        ):
            events.record(
                events.NUMPY_ACTION,
                self.requested_id,
                f"step() received a numpy integer action ({type(action).__module__}."
                f"{type(action).__name__}); the layer passed it on as a Python int",
            )
            return int(action)
        return action

    def seed(self, seed: int | None = None) -> list[int | None]:
        """Classic `env.seed(s)`: use `s` at the next reset; return `[s]`."""
        events.record(
            events.LEGACY_SEED_CALL,
            self.requested_id,
            "env.seed() is the classic API; "
            "the layer seeds the next reset() with it (gymnasium: env.reset(seed=...))",
        )
        self._next_seed = seed
        return [seed]

    def render(self, mode: str | None = None, **kwargs: Any) -> Any:
        """Draw the environment the classic way.

        With no mode (or `"human"`), when the env was not made with a render mode, nothing is drawn and
        None is returned: there is no window to draw into. Any other mode the environment supports
        (`"rgb_array"`, `"ansi"`) returns what gymnasium's render gives in that mode.

        Raises:
            UnsupportedRenderModeError: the environment cannot draw in `mode`.
        """
        own_mode = self.gymnasium_env.render_mode
        if own_mode is not None and mode in (None, own_mode):
            return self.gymnasium_env.render()
        if mode in (None, "human"):
            if not self._render_recorded:
                self._render_recorded = True
                events.record(
                    events.RENDER_WITHOUT_MODE,
                    self.requested_id,
                    f"render({'' if mode is None else repr(mode)}) would open a window; "
                    "there is none, so nothing was drawn (pass render_mode='rgb_array' to gym.make to get frames)",  # noqa: E501
                )
            return None
        return self._render_in(mode)

    def _render_in(self, mode: str) -> Any:
        base = self.gymnasium_env.unwrapped
        supported = base.metadata.get("render_modes", [])
        if mode not in supported:
            raise UnsupportedRenderModeError(
                f"{self.requested_id} cannot render in mode {mode!r}; "
                f"it supports {', '.join(map(repr, supported)) or 'no mode at all'}. Use one of those."
            )
        previous = base.render_mode
        base.render_mode = mode
        try:
            return base.render()
        finally:
            base.render_mode = previous

    def close(self) -> None:
        """Close the environment."""
        self.gymnasium_env.close()

    @property
    def unwrapped(self) -> gymnasium.Env[Any, Any]:
        """The innermost gymnasium environment (its own API is gymnasium's)."""
        return self.gymnasium_env.unwrapped

    @property
    def spec(self) -> Any:
        """The gymnasium spec of the environment actually made."""
        return self.gymnasium_env.spec

    @property
    def action_space(self) -> spaces.Space[Any]:
        """The action space."""
        return self.gymnasium_env.action_space

    @property
    def observation_space(self) -> spaces.Space[Any]:
        """The observation space."""
        return self.gymnasium_env.observation_space

    @property
    def metadata(self) -> dict[str, Any]:
        """The environment's metadata."""
        return self.gymnasium_env.metadata

    @property
    def nS(self) -> int:
        """Classic toy-text envs' number of states (`observation_space.n`), which the 2018 labs read."""
        return self._discrete_size("nS", self.gymnasium_env.observation_space)

    @property
    def nA(self) -> int:
        """Classic toy-text envs' number of actions (`action_space.n`)."""
        return self._discrete_size("nA", self.gymnasium_env.action_space)

    def _discrete_size(self, name: str, space: spaces.Space[Any]) -> int:
        if not isinstance(space, spaces.Discrete):
            raise AttributeError(f"the {self.requested_id} environment has no attribute {name!r}")
        return int(space.n)

    @property
    def np_random(self) -> np.random.Generator:
        """The environment's random generator."""
        return self.gymnasium_env.np_random

    @property
    def env(self) -> ClassicEnv:
        """The next level of `gym.make`'s chain: `gym.make(id).env` has no time limit (one view, kept).

        Every gym wrapped a made env in `TimeLimit` outermost; the second lab's texts step
        `gym.make(name).env` so that FrozenLake episodes run to their end, and 2023's files read
        `env.env.env.P`. The view steps the same gymnasium env (so a recorder sees every step) and ignores
        the truncation the limit reports. The raw env (`len(SERVED_CHAIN)` levels down) has no `env`.
        """
        if self.level >= len(SERVED_CHAIN):
            raise AttributeError(f"the {self.requested_id} environment has no attribute 'env'")
        if self._inner_view is None:
            self._inner_view = ClassicEnv(
                self.gymnasium_env, self.requested_id, self.api, level=self.level + 1
            )
        return self._inner_view

    def _cut_by_time_limit(self) -> bool:
        return limit_reached(self._time_limit())

    @property
    def _max_episode_steps(self) -> int | None:
        """Classic `TimeLimit`'s step limit, which classic code read (and set) on the env; None if none."""
        limit = self._time_limit() if self.time_limit else None
        return None if limit is None else limit._max_episode_steps

    @_max_episode_steps.setter
    def _max_episode_steps(self, steps: int) -> None:
        limit = self._time_limit()
        if limit is None:
            raise AttributeError(f"the {self.requested_id} environment has no step limit to change")
        limit._max_episode_steps = steps

    def _time_limit(self) -> TimeLimit[Any, Any] | None:
        return time_limit_of(self.gymnasium_env)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(f"accessing private attribute {name!r} of a gym environment is prohibited")
        env = self.__dict__.get("gymnasium_env")
        if env is None:
            raise AttributeError(name)
        if name == "env":  # only when the property refused: the view has no inner env
            raise AttributeError(f"the {self.requested_id} environment has no attribute 'env'")
        try:
            if self.__dict__.get("level", 0) >= len(SERVED_CHAIN):  # the raw env's own attribute
                return getattr(env.unwrapped, name)
            return env.get_wrapper_attr(name)
        except AttributeError:
            raise AttributeError(f"the {self.requested_id} environment has no attribute {name!r}") from None

    def __enter__(self) -> ClassicEnv:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<ClassicEnv{self.gymnasium_env}>"
