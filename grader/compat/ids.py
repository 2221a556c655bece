"""Map the environment ids the lab uses (classic gym) to gymnasium 1.4 ids and arguments."""

from __future__ import annotations

import difflib
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import gymnasium

from .errors import RetiredEnvironmentError, UnknownEnvironmentError


@dataclass(frozen=True)
class EnvTarget:
    """What `gymnasium.make` must be called with to get the game a classic id named.

    Attributes:
        gymnasium_id: the id registered with gymnasium 1.4 (or by `register_envs`).
        kwargs: constructor arguments that make the gymnasium env play the classic game.
        note: why the id or arguments differ from the classic ones; empty when nothing was renamed.
    """

    gymnasium_id: str
    kwargs: dict[str, Any] = field(default_factory=dict)
    note: str = ""

    def merged_kwargs(self, student_kwargs: Mapping[str, Any]) -> dict[str, Any]:
        """Return the target's arguments overridden by the student's own (the student wins)."""
        return {**self.kwargs, **student_kwargs}


@dataclass(frozen=True)
class _LabEntry:
    gymnasium_id: str
    kwargs: Mapping[str, Any]
    note: str


_SAME_GAME = ""

# Classic ids (gym 0.17 to 0.21, the gym the lab was written for) and the gymnasium 1.4 env with the
# same dynamics. Every entry was checked against both sources; see the note when they are not identical.
_LAB_TABLE: dict[str, _LabEntry] = {
    "Blackjack-v0": _LabEntry(
        "Blackjack-v1",
        {"natural": False, "sab": False},
        "gymnasium calls it Blackjack-v1, whose registered default sab=True is a different game (a player natural wins outright); "  # noqa: E501
        "natural=False, sab=False is classic Blackjack-v0",
    ),
    "Taxi-v3": _LabEntry(
        "Taxi-v4",
        {},
        "gymnasium calls it Taxi-v4; v4 only changed the optional is_rainy/fickle_passenger modes",
    ),
    "CartPole-v0": _LabEntry("CartPole-v0", {}, _SAME_GAME),
    "CartPole-v1": _LabEntry("CartPole-v1", {}, _SAME_GAME),
    "MountainCar-v0": _LabEntry("MountainCar-v0", {}, _SAME_GAME),
    "MountainCarContinuous-v0": _LabEntry("MountainCarContinuous-v0", {}, _SAME_GAME),
    "Acrobot-v1": _LabEntry("Acrobot-v1", {}, _SAME_GAME),
    "Pendulum-v0": _LabEntry(
        "Pendulum-v1",
        {},
        "gymnasium calls it Pendulum-v1; not identical: "
        "v0 advanced the angle with the velocity before clipping it to [-8, 8] and v1 after, so trajectories differ once the pendulum spins that fast",  # noqa: E501
    ),
    "FrozenLake-v0": _LabEntry(
        "FrozenLake-v1",
        {},
        "gymnasium calls it FrozenLake-v1; same map, same is_slippery default, same transitions",
    ),
    "FrozenLake8x8-v0": _LabEntry(
        "FrozenLake8x8-v1",
        {},
        "gymnasium calls it FrozenLake8x8-v1; same map, same is_slippery default, same transitions",
    ),
    "NChain-v0": _LabEntry("NChain-v0", {}, _SAME_GAME),
    "GuessingGame-v0": _LabEntry("GuessingGame-v0", {}, _SAME_GAME),
}

# The id the lab itself uses for each family it mentions: the one named in error messages.
_LAB_FAMILY_ID = {
    "Blackjack": "Blackjack-v0",
    "Taxi": "Taxi-v3",
    "CartPole": "CartPole-v0",
    "MountainCar": "MountainCar-v0",
    "Acrobot": "Acrobot-v1",
    "NChain": "NChain-v0",
    "GuessingGame": "GuessingGame-v0",
}

_ID_PATTERN = re.compile(r"^(?P<name>.+?)(?:-v(?P<version>\d+))?$")


def lab_ids() -> tuple[str, ...]:
    """The classic ids this layer maps, in the order of the table."""
    return tuple(_LAB_TABLE)


def resolve_env_id(env_id: str) -> EnvTarget:
    """Return the gymnasium id and arguments that play the game `env_id` named in classic gym.

    Lab ids map through the table above; any other id registered with gymnasium passes through
    unchanged. Resolution is pure: it reads gymnasium's registry but never registers anything.

    Args:
        env_id: the id the student passed to `gym.make` (e.g. `"Blackjack-v0"`).

    Returns:
        The target; `kwargs` is a fresh dict the caller may modify.

    Raises:
        RetiredEnvironmentError: `env_id` names a known game with a version that was retired before the
            lab, never existed, or is missing; the message names the id the lab uses.
        UnknownEnvironmentError: `env_id` names no known game; the message suggests close matches.
    """
    if not isinstance(env_id, str):
        raise UnknownEnvironmentError(
            f"gym.make expects an environment id string such as 'Taxi-v3', found {type(env_id).__name__} {env_id!r}. "  # noqa: E501
            "Pass the id as a string."
        )
    entry = _LAB_TABLE.get(env_id)
    if entry is not None:
        return EnvTarget(entry.gymnasium_id, dict(entry.kwargs), entry.note)
    if env_id in gymnasium.envs.registry:
        return EnvTarget(env_id, {}, _SAME_GAME)
    raise _unresolvable(env_id)


def _known_ids() -> list[str]:
    return list(_LAB_TABLE) + [known for known in gymnasium.envs.registry if known not in _LAB_TABLE]


def _split(env_id: str) -> tuple[str, int | None]:
    match = _ID_PATTERN.match(env_id)
    if match is None:
        return env_id, None
    version = match.group("version")
    return match.group("name"), None if version is None else int(version)


def _unresolvable(env_id: str) -> UnknownEnvironmentError:
    name, version = _split(env_id)
    family = [known for known in _known_ids() if _split(known)[0] == name]
    if family:
        return _wrong_version(env_id, name, version, family)
    return _unknown(env_id)


def _wrong_version(env_id: str, name: str, version: int | None, family: list[str]) -> RetiredEnvironmentError:
    lab_id = _LAB_FAMILY_ID.get(name)
    if lab_id is not None:
        lab_version = _split(lab_id)[1]
        if version is None:
            problem = f"{env_id} has no version"
        elif lab_version is not None and version < lab_version:
            problem = f"{env_id} was retired before this lab"
        else:
            problem = f"{env_id} never existed"
        return RetiredEnvironmentError(
            f"gym.make({env_id!r}): {problem}; the lab uses {lab_id}. Write gym.make({lab_id!r})."
        )
    newest = max(family, key=lambda known: _split(known)[1] or 0)
    return RetiredEnvironmentError(
        f"gym.make({env_id!r}): {env_id} is not available in gymnasium {gymnasium.__version__}, which has {', '.join(sorted(family))}. "  # noqa: E501
        f"The lab does not use this game; if you need it, read the documentation of {newest} first: "
        f"its rules may differ from {env_id}'s."
    )


def _unknown(env_id: str) -> UnknownEnvironmentError:
    candidates = [known for known in _known_ids() if "/" not in known or "/" in env_id]
    by_lower = {candidate.lower(): candidate for candidate in reversed(candidates)}
    if env_id.lower() in by_lower:
        close = [env_id.lower()]
    else:
        close = difflib.get_close_matches(env_id.lower(), list(by_lower), n=2, cutoff=0.75)
    if close:
        hint = "Did you mean " + " or ".join(repr(by_lower[match]) for match in close) + "?"
    else:
        hint = "The lab uses " + ", ".join(_LAB_FAMILY_ID.values()) + "."
    return UnknownEnvironmentError(
        f"gym.make({env_id!r}): "
        f"no environment of this lab or of gymnasium {gymnasium.__version__} is called {env_id!r}. {hint}"
    )
