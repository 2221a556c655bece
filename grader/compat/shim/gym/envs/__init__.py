"""`gym.envs`: the registry with the classic methods (`from gym import envs; envs.registry.all()`)."""

from __future__ import annotations

from collections.abc import Iterator, Mapping, ValuesView

import gymnasium
from gymnasium.envs.registration import EnvSpec

from grader.compat.ids import resolve_env_id
from grader.compat.make import make

__all__ = ["make", "register", "registry", "spec"]

register = gymnasium.register


class ClassicRegistry(Mapping[str, EnvSpec]):
    """gymnasium's registry, read when used, with classic gym's `all()`, `spec()` and `env_specs`."""

    def __getitem__(self, env_id: str) -> EnvSpec:
        return gymnasium.envs.registry[env_id]

    def __iter__(self) -> Iterator[str]:
        return iter(gymnasium.envs.registry)

    def __len__(self) -> int:
        return len(gymnasium.envs.registry)

    def all(self) -> ValuesView[EnvSpec]:
        """Every registered spec, as classic `registry.all()` returned them."""
        return gymnasium.envs.registry.values()

    def spec(self, env_id: str) -> EnvSpec:
        """The spec of the environment that `gym.make(env_id)` makes."""
        return gymnasium.spec(resolve_env_id(env_id).gymnasium_id)

    @property
    def env_specs(self) -> dict[str, EnvSpec]:
        """The id-to-spec dict classic code read directly."""
        return gymnasium.envs.registry


registry = ClassicRegistry()
spec = registry.spec
