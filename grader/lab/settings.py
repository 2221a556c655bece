"""Settings every `[problems.<id>]` table has, and the shared kinds a problem's own settings model extends."""

from __future__ import annotations

from typing import Annotated, Self

from pydantic import BaseModel, ConfigDict, Field, PrivateAttr

from grader.errors import PlanError
from grader.lab.games import Game, GameRules, allowed_games, game_names
from grader.lab.ids import ProblemId
from grader.report import Visibility

Probability = Annotated[float, Field(gt=0.0, lt=1.0)]
Share = Annotated[float, Field(ge=0.0, le=1.0)]
"""A share of a problem's points, 0 to 1 inclusive (a deduction, a part's weight)."""


class StrictModel(BaseModel):
    """A frozen model that refuses unknown fields (a misspelt setting is an error, never ignored)."""

    model_config = ConfigDict(extra="forbid", frozen=True)


class ProblemConfig(StrictModel):
    """Settings every problem has."""

    title: str = Field(
        description="Heading shown in the report; default: the problem's title in grader/lab/problems.py."
    )
    points: float = Field(
        ge=0.0,
        description="Points the problem is worth; 0 reports it without scoring. Default: grader/lab/problems.py.",  # noqa: E501
    )
    enabled: bool = Field(
        default=True,
        description="False skips the problem entirely (no calls, no points). Default: grader/lab/problems.py.",  # noqa: E501
    )
    call_seconds: float = Field(gt=0.0, description="Wall-clock limit of ONE call of the student's function.")
    expected_seconds: float = Field(
        ge=0.0, description="Typical total time of the problem's calls; slowest problems are started first."
    )
    visibility: Visibility = Field(
        default="visible",
        description="When students see this problem's result and feedback in the service: "
        "'visible' (at once), 'after_due_date' (once GYMGRADE_DUE_DATE has passed) or 'hidden' (instructors only).",  # noqa: E501
    )
    _problem: ProblemId | None = PrivateAttr(default=None)
    _games: tuple[Game, ...] = PrivateAttr(default=())

    @property
    def problem_id(self) -> ProblemId:
        """The id of the problem these settings were loaded for.

        Raises:
            PlanError: The settings were built by hand, not loaded (use `for_problem`).
        """
        if self._problem is None:
            raise PlanError(
                f"expected {type(self).__name__} loaded for a problem, found unbound settings: load them "
                "with grader.lab.assignment.load_config or bind them with .for_problem(id)"
            )
        return self._problem

    def for_problem(self, problem_id: ProblemId, games: tuple[Game, ...] = ()) -> Self:
        """These settings bound to the problem they configure (what the loader does with every table).

        Args:
            problem_id: The problem's id.
            games: The games the problem's declaration accepts (`Problem.games`); empty when it plays none.

        Raises:
            ValueError: A setting does not suit the problem (the loader reports it under the table).
        """
        bound = self.model_copy()
        bound._problem = problem_id
        bound._games = tuple(games)
        return bound

    def game_rules(self) -> GameRules | None:
        """The games the problem's episodes must be played in; None: its calls play none."""
        return None


class PlayedProblemConfig(ProblemConfig):
    """Settings of a problem whose function plays episodes in an environment."""

    accepted_envs: list[str] | None = Field(
        default=None,
        description="The games the episodes may be played in, by id (the problem's declaration lists them, e.g. Blackjack-v0/Blackjack-v1, CartPole-v0/CartPole-v1, MountainCar-v0, Taxi-v3); "  # noqa: E501
        "absent = all of them.",
    )

    post_terminal_steps_deduction: Share = Field(
        default=0.0,
        description="Share of the points deducted from a passing verdict when games kept stepping after they were over (steps that change nothing counted: each game is judged up to its end); "  # noqa: E501
        "0 = a note in the feedback only.",
    )

    def for_problem(self, problem_id: ProblemId, games: tuple[Game, ...] = ()) -> Self:
        """These settings bound to their problem, once `accepted_envs` names only games it accepts.

        Raises:
            ValueError: The problem's declaration names no games, or `accepted_envs` names another game.
        """
        if not games:
            raise ValueError(
                f"{problem_id} plays episodes, so its declaration must list the games it accepts (Problem(games=...)); "  # noqa: E501
                "found none"
            )
        accepted = game_names(games)
        chosen = self.accepted_envs
        if chosen is not None and (not chosen or not set(chosen) <= set(accepted)):
            raise ValueError(
                f"accepted_envs must be a non-empty list of {', '.join(accepted)}; found {chosen}"
            )
        return super().for_problem(problem_id, games)

    def game_rules(self) -> GameRules:
        """The games the problem's episodes must be played in (`accepted_envs`, else all it accepts)."""
        return allowed_games(self._games, self.accepted_envs, problem=self.problem_id)


class CountedStepsConfig(PlayedProblemConfig):
    """Settings of a problem whose function returns the length of the episode it played."""

    uncounted_steps_deduction: Share = Field(
        default=0.0,
        description="Share of the problem's points deducted when every returned count misses exactly the steps taken before the counted loop (the lab-era 'one random step first' pattern); "  # noqa: E501
        "the verdict follows the replayed episodes either way.",
    )
