"""`gym.make`'s wrapper chain as each gym of the labs built it, and its levels served to student code.

What `gym.make("FrozenLake-v1")` returned, read from each release's `envs/registration.py` and `core.py`:

- gym 0.10 - 0.12.0 (2018): TimeLimit > FrozenLakeEnv; no attribute read through wrappers
  (`Wrapper.__getattr__` came in 0.12.1), hence the 2018 text's `gym.make(name).env` and `env.env.P`;
- gym 0.12.1 - 0.21 (2019-2021): TimeLimit > FrozenLakeEnv; every public name forwarded (`env.P`, `env.nS`);
- gym 0.22 - 0.23 (2022): TimeLimit > OrderEnforcing > FrozenLakeEnv (no more `nS`, `nA`); forwarded;
- gym 0.24 and 0.26, gymnasium 0.26 - 1.x: TimeLimit > OrderEnforcing > PassiveEnvChecker > FrozenLakeEnv;
  forwarded (gymnasium 0.29 with a deprecation warning), except in gymnasium 1.x, which forwards nothing;
- gym 0.25: TimeLimit > OrderEnforcing > StepAPICompatibility > PassiveEnvChecker > FrozenLakeEnv.

`gym.make(id).env` is the chain below `TimeLimit` in every one of them: its episodes have no time limit, the
second lab's way to play FrozenLake to the end. `env.unwrapped` is the raw env.

The grader serves `SERVED_CHAIN` (gym 0.26's and gymnasium's, the deepest but for 0.25's short-lived step
adapter) to code of every edition, and forwards public attribute reads at every level: each year's idioms
work (`gym.make(id).env.P` of 2018-2022, `env.env.env.P` of 2023, `gym.make(id).env.P` of gymnasium 0.29),
and what a deeper chain adds (an `env.env` that 2018's gym lacked) changes nothing an older file does.

Every level steps one object, the sandbox's recorder (or gymnasium's own chain outside the sandbox), so each
episode is recorded whichever level the student steps; a level below the time limit hides the truncation
the limit reports, as the env inside `TimeLimit` never saw it. `served_levels` builds the levels below a
gymnasium chain's top for code that holds gymnasium objects (`import gymnasium as gym`); the compat `gym`
serves the same chain with its own API per level (`grader.compat.adapter.ClassicEnv`).
"""

from __future__ import annotations

import copy
from typing import Any

import gymnasium
from gymnasium.wrappers import TimeLimit

from . import events

SERVED_CHAIN = ("TimeLimit", "OrderEnforcing", "PassiveEnvChecker")
"""The wrappers above the raw env that the compat `gym`'s `gym.make` serves, outermost first."""


def real_env(env: Any) -> Any:
    """The gymnasium object a served level stands for (itself for anything else)."""
    served = getattr(type(env), "served_of", None)
    return env if served is None else served(env)


def time_limit_of(env: Any) -> TimeLimit[Any, Any] | None:
    """The first `TimeLimit` of the real chain under `env` (served levels read as what they stand for)."""
    env = real_env(env)
    while isinstance(env, gymnasium.Wrapper):
        if isinstance(env, TimeLimit):
            return env
        env = real_env(env.env)
    return None


def limit_reached(limit: TimeLimit[Any, Any] | None) -> bool:
    """Whether `limit` has cut the current episode (its step count reached its maximum)."""
    if limit is None:
        return False
    elapsed = limit._elapsed_steps
    return elapsed is not None and elapsed >= limit._max_episode_steps


def below_time_limit(result: tuple[Any, ...], limit: TimeLimit[Any, Any] | None) -> tuple[Any, ...]:
    """A gymnasium step's result as a level below `limit` sees it: no truncation by the limit."""
    if not limit_reached(limit):
        return result
    observation, reward, terminated, _, info = result
    return observation, reward, terminated, False, info


def served_levels(top: gymnasium.Env[Any, Any], stepper: gymnasium.Env[Any, Any]) -> gymnasium.Env[Any, Any]:
    """The level below `top` (a real gymnasium chain) as served: every level's steps go through `stepper`.

    Returns a `ServedWrapper` for each real wrapper below `top` and a `ServedRaw` for the raw env (or the
    `ServedRaw` at once when `top` is raw). A level under the chain's `TimeLimit` hides its truncation.
    """
    limit = top if isinstance(top, TimeLimit) else None
    if not isinstance(top, gymnasium.Wrapper):
        return ServedRaw(top, stepper, limit)
    return _serve(top.env, stepper, limit)


def _serve(
    real: gymnasium.Env[Any, Any], stepper: gymnasium.Env[Any, Any], limit: TimeLimit[Any, Any] | None
) -> gymnasium.Env[Any, Any]:
    if isinstance(real, gymnasium.Wrapper):
        return ServedWrapper(real, stepper, limit)
    return ServedRaw(real, stepper, limit)


class _PlayedThroughStepper:
    """What every served level does alike: reset, step and close through the chain's stepper (so each
    episode is recorded at whichever level it is played; below the time limit its truncation is not seen),
    and render as the real object it stands for does."""

    served: gymnasium.Env[Any, Any]
    stepper: gymnasium.Env[Any, Any]
    limit: TimeLimit[Any, Any] | None

    def reset(self, *, seed: Any = None, options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        """Reset through the stepper (the recorder deals the start)."""
        return self.stepper.reset(seed=seed, options=options)  # type: ignore[no-any-return]

    def step(self, action: Any) -> tuple[Any, Any, bool, bool, dict[str, Any]]:
        """Step through the stepper; below the time limit (for the raw env: always), no truncation by it."""
        return below_time_limit(self.stepper.step(action), self.limit)  # type: ignore[return-value]

    def render(self) -> Any:
        """Render as the real wrapper or raw env does."""
        return self.served.render()

    def close(self) -> None:
        """Close the whole env (through the stepper, which notes a closed env the grader passed)."""
        self.stepper.close()


class ServedWrapper(_PlayedThroughStepper, gymnasium.Wrapper[Any, Any, Any, Any]):
    """A wrapper of gymnasium's chain as student code sees it: `env.env` of `gym.make`'s env, and so on.

    Its `env` is the next served level; `reset` and `step` go through the chain's stepper (the recorder), so
    every episode is recorded at whichever level it is played; spaces, spec, rendering and attributes are
    the real wrapper's. Public attribute reads go down the chain, as gymnasium before 1.0 forwarded them (a
    compat event says so).
    """

    def __init__(
        self,
        real: gymnasium.Wrapper[Any, Any, Any, Any],
        stepper: gymnasium.Env[Any, Any],
        limit: TimeLimit[Any, Any] | None,
    ) -> None:
        """Serve `real`, stepped through `stepper`; `limit` is the chain's `TimeLimit` above it, if any."""
        below = limit if limit is not None else (real if isinstance(real, TimeLimit) else None)
        super().__init__(_serve(real.env, stepper, below))
        self.served = real
        self.stepper = stepper
        self.limit = limit

    @staticmethod
    def served_of(level: ServedWrapper) -> gymnasium.Env[Any, Any]:
        """The real wrapper `level` stands for (read by `real_env`)."""
        return level.served

    @property
    def spec(self) -> Any:  # type: ignore[override]
        """The real wrapper's spec."""
        return self.served.spec

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(f"accessing private attribute {name!r} of a gym environment is prohibited")
        served = self.__dict__.get("served")
        if served is None:
            raise AttributeError(name)
        value = served.get_wrapper_attr(name)
        spec = served.spec
        events.record(
            events.WRAPPER_ATTRIBUTE,
            f"{spec.id if spec is not None else 'env'}: env.{name}",
            f"env.{name} was read through gymnasium's wrappers, which gymnasium 1.x no longer forwards; "
            f"the grader forwarded it (env.unwrapped.{name} works everywhere)",
        )
        return value

    def __deepcopy__(self, memo: dict[int, Any]) -> Any:
        """A copy of the real wrapper: a new env, not gym.make's, so not stepped through the stepper (as a
        copy of gymnasium's own wrapper was not)."""
        return copy.deepcopy(self.served, memo)

    def __str__(self) -> str:
        return str(self.served)

    def __repr__(self) -> str:
        return repr(self.served)


_RAW_OWN = frozenset({"served", "stepper", "limit"})


class ServedRaw(_PlayedThroughStepper, gymnasium.Env[Any, Any]):
    """The raw env as the last `env.env` of the chain: its own attributes read and written, its episodes
    stepped through the chain's stepper (recorded), with no time limit."""

    def __init__(
        self,
        real: gymnasium.Env[Any, Any],
        stepper: gymnasium.Env[Any, Any],
        limit: TimeLimit[Any, Any] | None,
    ) -> None:
        """Serve the raw env `real`, stepped through `stepper`; `limit` is the chain's `TimeLimit`, if any."""
        object.__setattr__(self, "served", real)
        object.__setattr__(self, "stepper", stepper)
        object.__setattr__(self, "limit", limit)

    @staticmethod
    def served_of(level: ServedRaw) -> gymnasium.Env[Any, Any]:
        """The raw env `level` stands for (read by `real_env`)."""
        return level.served  # type: ignore[no-any-return]

    @property
    def unwrapped(self) -> gymnasium.Env[Any, Any]:
        """Gymnasium's raw env itself, as `env.unwrapped` is everywhere (read for `P`; not recorded if
        stepped: code that rigs `type(env.unwrapped)` rigs gymnasium's class, which the replay tells)."""
        return self.served  # type: ignore[no-any-return]

    @property
    def spec(self) -> Any:  # type: ignore[override]
        return self.served.spec

    @property
    def action_space(self) -> Any:  # type: ignore[override]
        return self.served.action_space

    @property
    def observation_space(self) -> Any:  # type: ignore[override]
        return self.served.observation_space

    @property
    def metadata(self) -> Any:  # type: ignore[override]
        return self.served.metadata

    @property
    def render_mode(self) -> Any:  # type: ignore[override]
        return self.served.render_mode

    @property  # type: ignore[misc]
    def np_random(self) -> Any:
        return self.served.np_random

    @property
    def np_random_seed(self) -> Any:
        return self.served.np_random_seed

    def has_wrapper_attr(self, name: str) -> bool:
        """Whether the raw env has `name`."""
        return hasattr(self.served, name)

    def get_wrapper_attr(self, name: str) -> Any:
        """The raw env's `name`."""
        return getattr(self.served, name)

    def set_wrapper_attr(self, name: str, value: Any, *, force: bool = True) -> bool:
        """Set the raw env's `name`."""
        setattr(self.served, name, value)
        return True

    def __getattr__(self, name: str) -> Any:
        served = self.__dict__.get("served")
        if served is None or name.startswith("__"):
            raise AttributeError(name)
        return getattr(served, name)

    def __setattr__(self, name: str, value: Any) -> None:
        if name in _RAW_OWN:
            object.__setattr__(self, name, value)
        else:
            setattr(self.served, name, value)

    def __deepcopy__(self, memo: dict[int, Any]) -> Any:
        """A copy of the raw env, as copying gymnasium's raw env gave (a new env, not stepped through the
        stepper: code that plays a copy ahead, to peek at its generator, plays it unrecorded as before)."""
        return copy.deepcopy(self.served, memo)

    def __copy__(self) -> Any:
        return copy.copy(self.served)

    def __str__(self) -> str:
        return str(self.served)

    def __repr__(self) -> str:
        return repr(self.served)
