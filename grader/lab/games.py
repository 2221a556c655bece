"""The environments problems may be played in: each game's accepted ids and rule arguments, declared once.

The lab was taught in several versions. The classic one names `Blackjack-v0` and `CartPole-v0`; later ones
name `Blackjack-v1` (registered with `sab=True`, Sutton and Barto's rules, the only Blackjack of gym 0.22+)
and `CartPole-v1` (500-step limit). Which games a problem accepts is a field of its declaration
(`grader.lab.registry.Problem.games`, the `*_GAMES` tuples below are the lab's); the assignment
configuration may restrict them (`accepted_envs = [...]` in the problem's table); checks grade each game
against its own exact expectations.
"""

from __future__ import annotations

import inspect
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cache
from typing import TYPE_CHECKING, Any

import gymnasium
from gymnasium.envs.registration import load_env_creator

from grader.compat import register_envs

if TYPE_CHECKING:
    from grader.sandbox.episode_log import EpisodeLog

# Constructor arguments that never change a game's rules.
_HARMLESS_KWARGS = frozenset({"render_mode"})


@dataclass(frozen=True)
class Game:
    """One environment a problem may be played in.

    Attributes:
        name: The id that plays it when made without arguments (`Blackjack-v1`); the configuration and
            the feedback use it.
        gymnasium_ids: Gymnasium ids that play it (the compat layer maps lab ids onto them).
        rules: Effective constructor arguments (registered defaults merged with the student's) that
            define the game, e.g. Blackjack's `sab`.
        free_kwargs: Further arguments a student may pass because they change nothing that is graded
            (Blackjack's `natural` only pays a natural 1.5 instead of 1; a win is still a win).
        description: How the feedback names the game.
    """

    name: str
    gymnasium_ids: tuple[str, ...]
    rules: Mapping[str, Any] = field(default_factory=dict)
    free_kwargs: frozenset[str] = frozenset()
    description: str = ""

    @property
    def sab(self) -> bool:
        """Whether the game is Blackjack with Sutton and Barto's rules (`sab=True`)."""
        return bool(self.rules.get("sab", False))

    def mismatch(self, log: EpisodeLog) -> str | None:
        """Why an episode's environment is not this game (None when it is)."""
        if log.env_id not in self.gymnasium_ids:
            return f"gymnasium {log.env_id} is not {self.name}"
        effective = {**default_kwargs(log.env_id), **dict(log.env_kwargs)}
        for name, value in self.rules.items():
            found = effective.get(name)
            if found != value:
                required, had = f"{name}={value!r}", f"{name}={found!r}"
                return f"{self.name} is played with {required}, but your environment had {had}"
        extra = sorted(set(log.env_kwargs) - set(self.rules) - self.free_kwargs - _HARMLESS_KWARGS)
        if extra:
            arguments = ", ".join(f"{name}={log.env_kwargs[name]!r}" for name in extra)
            return f"you made {log.requested_id!r} with {arguments}"
        return None


BLACKJACK_V0 = Game(
    "Blackjack-v0",
    ("Blackjack-v1",),
    {"sab": False},
    frozenset({"natural"}),
    "Blackjack-v0 (classic rules, sab=False)",
)
BLACKJACK_V1 = Game(
    "Blackjack-v1",
    ("Blackjack-v1",),
    {"sab": True},
    frozenset({"natural"}),
    "Blackjack-v1 (Sutton and Barto's rules, sab=True: a natural wins unless the dealer has one too)",
)
CARTPOLE_V0 = Game("CartPole-v0", ("CartPole-v0",), description="CartPole-v0 (200-step limit)")
CARTPOLE_V1 = Game("CartPole-v1", ("CartPole-v1",), description="CartPole-v1 (500-step limit)")
MOUNTAIN_CAR = Game("MountainCar-v0", ("MountainCar-v0",), description="MountainCar-v0")
TAXI = Game(
    "Taxi-v3",
    ("Taxi-v4", "Taxi-v3"),
    {"is_rainy": False, "fickle_passenger": False},
    description="Taxi-v3",
)
GUESSING_GAME = Game("GuessingGame-v0", ("GuessingGame-v0",), description="GuessingGame-v0")

FROZEN_LAKE_FREE_KWARGS = frozenset({"max_episode_steps"})
"""A FrozenLake episode may be cut by any time limit: the second lab's checks value a policy exactly under
the limit actually played (`reference.oracles.mdp.return_moments(steps=...)`)."""


def frozen_lake_game(map_name: str, *, slippery: bool) -> Game:
    """The second lab's FrozenLake on one map, slippery or not (gymnasium's `FrozenLake-v1` and the 8x8 id).

    The old ids `FrozenLake-v0` and `FrozenLake8x8-v0` resolve to these (`grader.compat.ids`); `desc` may be
    passed as None only (a map of one's own is another game).
    """
    ids = ("FrozenLake-v1", "FrozenLake8x8-v1") if map_name == "8x8" else ("FrozenLake-v1",)
    kind = "slippery" if slippery else "deterministic"
    name = "FrozenLake8x8-v1" if map_name == "8x8" else "FrozenLake-v1"
    return Game(
        name if slippery else f"{name} (is_slippery=False)",
        ids,
        {
            "desc": None,
            "map_name": map_name,
            "is_slippery": slippery,
            "success_rate": 1.0 / 3.0,
            "reward_schedule": (1, 0, 0),
        },
        FROZEN_LAKE_FREE_KWARGS,
        f"FrozenLake {map_name} ({kind})",
    )


FROZEN_LAKE_4X4 = frozen_lake_game("4x4", slippery=True)
FROZEN_LAKE_8X8 = frozen_lake_game("8x8", slippery=True)
FROZEN_LAKE_4X4_STILL = frozen_lake_game("4x4", slippery=False)
FROZEN_LAKE_8X8_STILL = frozen_lake_game("8x8", slippery=False)
FROZEN_LAKE_GAMES = (FROZEN_LAKE_4X4, FROZEN_LAKE_8X8)
"""The lakes the second lab plays (`frozen_lake`, `model_comparison`): slippery, as its texts make them."""
RUN_SIMULATION_GAMES = (FROZEN_LAKE_4X4, FROZEN_LAKE_8X8, FROZEN_LAKE_4X4_STILL, FROZEN_LAKE_8X8_STILL, TAXI)
"""The envs the grader passes to `run_simulation(env, policy, beta)`: both lakes, slippery and not, and Taxi
(rewards on every step: a return of the last reward only shows)."""

BLACKJACK_GAMES = (BLACKJACK_V0, BLACKJACK_V1)
CARTPOLE_GAMES = (CARTPOLE_V0, CARTPOLE_V1)
MOUNTAIN_CAR_GAMES = (MOUNTAIN_CAR,)
TAXI_GAMES = (TAXI,)
GUESSING_GAMES = (GUESSING_GAME,)
"""The games the lab's problems accept by default, the classic lab's first (problem declarations use them)."""


def game_names(accepted: Sequence[Game]) -> tuple[str, ...]:
    """The names a configuration may list in a problem's `accepted_envs`."""
    return tuple(game.name for game in accepted)


@dataclass(frozen=True)
class GameRules:
    """Which environments a problem's episodes may be played in.

    Attributes:
        lab_id: The id the classic lab uses (named in feedback).
        games: The accepted games, the lab's first.
    """

    lab_id: str
    games: tuple[Game, ...]

    @property
    def names(self) -> str:
        """The accepted games' names, for feedback ("Blackjack-v0 or Blackjack-v1")."""
        return " or ".join(game.name for game in self.games)

    def game_of(self, log: EpisodeLog) -> Game | None:
        """The accepted game an episode was played in, or None."""
        return next((game for game in self.games if game.mismatch(log) is None), None)

    def problem_with(self, log: EpisodeLog) -> str | None:
        """Why an episode's environment is none of the accepted games, or None when it is one."""
        if self.game_of(log) is not None:
            return None
        same_id = [game for game in self.games if log.env_id in game.gymnasium_ids]
        if not same_id:
            return (
                f"the episodes must be played in {self.names}, but you made {log.requested_id!r} (gymnasium {log.env_id}), a different game: "  # noqa: E501
                f"use gym.make({self.lab_id!r})"
            )
        reason = same_id[0].mismatch(log)
        return (
            f"{reason}, which changes the game: this assignment accepts {self.names}; "
            f"make the environment with gym.make({same_id[0].name!r}) and no extra arguments"
        )

    def played_game(self, logs: Iterable[EpisodeLog]) -> Game | str:
        """The one accepted game all the logs were played in, or why there is not one.

        Call after `problem_with` accepted every log. No episode at all counts as the lab's game.
        """
        played: dict[str, Game] = {}
        environments: set[str] = set()
        for log in logs:
            environment = log.environment
            if environment in environments:  # the same id and arguments: the same game
                continue
            environments.add(environment)
            game = self.game_of(log)
            if game is not None:
                played.setdefault(game.name, game)
        if len(played) > 1:
            games = " and ".join(game.description for game in played.values())
            return (
                f"your episodes were played in {games}; "
                "each problem is graded against one game's exact results: "
                "make every environment of the problem the same way"
            )
        return next(iter(played.values()), self.games[0])


def allowed_games(
    accepted: Sequence[Game], names: Sequence[str] | None = None, *, problem: str = "this problem"
) -> GameRules:
    """The games a problem's episodes may be played in.

    Args:
        accepted: The games the problem's declaration accepts, its lab's first.
        names: The configuration's `accepted_envs` for the problem (a subset of `game_names(accepted)`),
            or None for every accepted game.
        problem: The problem's id, for the error message.

    Raises:
        ValueError: The problem accepts no games, or a name is not one of its accepted games.
    """
    accepted = tuple(accepted)
    if not accepted:
        raise ValueError(f"{problem} declares no games: its calls play no episodes")
    if names is None:
        return GameRules(accepted[0].name, accepted)
    unknown = [name for name in names if name not in game_names(accepted)]
    if unknown or not names:
        accepted_names = ", ".join(game_names(accepted))
        raise ValueError(f"{problem} accepts the games {accepted_names}; found {list(names)}")
    chosen = tuple(game for game in accepted if game.name in names)
    return GameRules(chosen[0].name, chosen)


@cache
def default_kwargs(env_id: str) -> dict[str, Any]:
    """The arguments an env gets when made without any: registered kwargs over constructor defaults.

    The ids gymgrade registers itself (`GuessingGame-v0`, ...) are registered first.
    """
    register_envs()
    spec = gymnasium.spec(env_id)
    creator = load_env_creator(spec.entry_point) if isinstance(spec.entry_point, str) else spec.entry_point
    parameters = inspect.signature(creator).parameters.values() if creator is not None else []
    defaults = {p.name: p.default for p in parameters if p.default is not inspect.Parameter.empty}
    return {**defaults, **spec.kwargs}
