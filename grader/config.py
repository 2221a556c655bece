"""The assignment configuration: points, time limits, sample sizes and thresholds, loaded from TOML."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from grader.errors import ConfigError
from grader.games import accepted_game_names
from grader.problems import PROBLEM_IDS, ProblemId
from grader.report import Visibility
from grader.sandbox.limits import Limits

DEFAULT_CONFIG_PATH = Path(__file__).with_name("assignment.toml")

Probability = Annotated[float, Field(gt=0.0, lt=1.0)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class ProblemConfig(_Strict):
    """Settings every problem has."""

    title: str = Field(description="Heading shown in the report, e.g. 'Problem 1: random Blackjack'.")
    points: float = Field(ge=0.0, description="Points the problem is worth; 0 reports it without scoring.")
    enabled: bool = Field(default=True, description="False skips the problem entirely (no calls, no points).")
    call_seconds: float = Field(gt=0.0, description="Wall-clock limit of ONE call of the student's function.")
    expected_seconds: float = Field(
        ge=0.0, description="Typical total time of the problem's calls; slowest problems are started first."
    )
    visibility: Visibility = Field(
        default="visible",
        description="When students see this problem's result and feedback in the service: 'visible' (at "
        "once), 'after_due_date' (once GYMGRADE_DUE_DATE has passed) or 'hidden' (instructors only).",
    )


class PlayedProblemConfig(ProblemConfig):
    """Settings of a problem whose function plays episodes in an environment."""

    accepted_envs: list[str] | None = Field(
        default=None,
        description="The games the episodes may be played in, by id (grader/games.py lists each "
        "problem's: Blackjack-v0/Blackjack-v1, CartPole-v0/CartPole-v1, MountainCar-v0, Taxi-v3); "
        "absent = all of them.",
    )

    @model_validator(mode="after")
    def _known_games(self) -> PlayedProblemConfig:
        problem: ProblemId = getattr(self, "kind")  # noqa: B009 (every subclass declares its kind)
        accepted = accepted_game_names(problem)
        chosen = self.accepted_envs
        if chosen is not None and (not chosen or not set(chosen) <= set(accepted)):
            raise ValueError(
                f"accepted_envs must be a non-empty list of {', '.join(accepted)}; found {chosen}"
            )
        return self


class CountedStepsConfig(PlayedProblemConfig):
    """Settings of a problem whose function returns the length of the episode it played."""

    uncounted_steps_deduction: float = Field(
        default=0.0,
        ge=0.0,
        le=1.0,
        description="Share of the problem's points deducted when every returned count misses exactly the "
        "steps taken before the counted loop (the lab-era 'one random step first' pattern); the verdict "
        "follows the replayed episodes either way.",
    )


class RandomBlackjackConfig(PlayedProblemConfig):
    """Problem 1: `random_blackjack(n)`."""

    kind: Literal["random_blackjack"] = "random_blackjack"
    games: int = Field(ge=100, description="The n passed to random_blackjack(n): games the student plays.")
    win_rate_alpha: Probability = Field(
        description="False-fail probability of the exact two-sided binomial test of the win count against "
        "the exact random-policy win probability."
    )
    action_alpha: Probability = Field(
        description="False-fail probability of EACH of the two random-action tests (hit frequency = 1/2; "
        "actions independent of the player's sum)."
    )


class BlackjackConfig(PlayedProblemConfig):
    """Problem 2: `blackjack(n)`."""

    kind: Literal["blackjack"] = "blackjack"
    thresholds: list[Annotated[int, Field(ge=0, le=21)]] = Field(
        min_length=1, description="The values of n blackjack(n) is called with, one call each."
    )
    games_per_call: int = Field(
        ge=1, description="Games each call must play (the lab says 10000); 0 is not allowed."
    )
    win_rate_alpha: Probability = Field(
        description="False-fail probability of the exact two-sided binomial test of EACH call's win count "
        "against the exact threshold-policy win probability."
    )

    @field_validator("thresholds")
    @classmethod
    def _distinct(cls, thresholds: list[int]) -> list[int]:
        if len(set(thresholds)) != len(thresholds):
            raise ValueError(f"expected distinct values of n, found {thresholds}")
        return thresholds


class CartpoleConfig(CountedStepsConfig):
    """Problem 3: `cartpole()`."""

    kind: Literal["cartpole"] = "cartpole"
    calls: int = Field(ge=1, description="How many times cartpole() is called (one episode each).")
    min_mean_steps: float = Field(ge=0.0, description="The mean episode length must be at least this.")
    min_steps: int = Field(ge=0, description="Every episode must last at least this many steps.")


class CarConfig(CountedStepsConfig):
    """Problem 4: `car()`."""

    kind: Literal["car"] = "car"
    calls: int = Field(ge=1, description="How many times car() is called (one episode each).")
    max_mean_steps: float = Field(gt=0.0, description="The mean episode length must be strictly below this.")


class TaxiConfig(PlayedProblemConfig):
    """Problem 5: `taxi()` or `taxi(q_table)`."""

    kind: Literal["taxi"] = "taxi"
    gamma: float = Field(
        gt=0.0,
        lt=1.0,
        description="Discount of the exact optimal Q-table passed when taxi takes a parameter.",
    )
    episodes_per_scenario: int = Field(
        ge=1, description="Episodes each scenario (random, Q-table) must play (the lab says 10000)."
    )
    mean_alpha: Probability = Field(
        description="False-fail probability of EACH two-sided z-test of a returned mean against its exact "
        "expectation (variance from the exact oracle)."
    )
    action_alpha: Probability = Field(
        description="False-fail probability of the chi-square test that the random scenario's actions are "
        "uniform over the 6 actions."
    )
    trained_slack: float = Field(
        ge=0.0,
        description="When taxi() trains its own table, its Q mean may fall this far below the optimal "
        "greedy return (on top of the z-test tolerance).",
    )


class FindQvaluesConfig(ProblemConfig):
    """The lab-provided `find_qvalues(env)`: reported, weight 0 by default."""

    kind: Literal["find_qvalues"] = "find_qvalues"
    env_id: str = Field(description="The environment id find_qvalues is called with (the lab's Taxi-v3).")
    run: Literal["when_scored", "always"] = Field(
        default="when_scored",
        description="'when_scored' (default) calls find_qvalues only when the problem is worth points (no "
        "other verdict needs it: taxi(q_table) receives the grader's exact table); 'always' calls it "
        "for feedback on its table even at 0 points.",
    )

    @property
    def called(self) -> bool:
        """Whether find_qvalues is called: it is worth points, or the configuration asks for it."""
        return self.points > 0 or self.run == "always"


_PROBLEM_CLASSES: dict[ProblemId, type[ProblemConfig]] = {
    "random_blackjack": RandomBlackjackConfig,
    "blackjack": BlackjackConfig,
    "cartpole": CartpoleConfig,
    "car": CarConfig,
    "taxi": TaxiConfig,
    "find_qvalues": FindQvaluesConfig,
}


class SandboxConfig(_Strict):
    """Resource limits of the sandbox (per child process); `call_seconds` comes from each problem."""

    import_seconds: float = Field(gt=0.0, description="Wall-clock limit for importing the submission.")
    cpu_seconds: int = Field(gt=0, description="CPU seconds one child may use over its life (backstop).")
    memory_bytes: int = Field(ge=1536 * 2**20, description="Memory of the child's process tree (>= 1.5 GiB).")
    max_pids: int = Field(gt=0, description="Processes and threads the child's tree may hold at once.")
    output_bytes: int = Field(gt=0, description="Student stdout/stderr kept per call (each).")
    scratch_bytes: int = Field(gt=0, description="Size of the writable scratch directory (HOME, TMPDIR).")
    file_bytes: int = Field(gt=0, description="Largest file the student may write.")
    open_files: int = Field(gt=0, description="File descriptors the child may hold.")
    frame_bytes: int = Field(gt=0, description="Largest result (return value + episode logs) accepted.")

    def to_limits(self, call_seconds: float) -> Limits:
        """The sandbox `Limits` for calls of one problem.

        Args:
            call_seconds: The problem's per-call wall-clock limit.
        """
        return Limits(call_seconds=call_seconds, **self.model_dump())


class ProblemTable(_Strict):
    """The `[problems.X]` tables of the file, each parsed with its problem's settings."""

    random_blackjack: RandomBlackjackConfig = Field(description="Problem 1: random_blackjack(n).")
    blackjack: BlackjackConfig = Field(description="Problem 2: blackjack(n).")
    cartpole: CartpoleConfig = Field(description="Problem 3: cartpole().")
    car: CarConfig = Field(description="Problem 4: car().")
    taxi: TaxiConfig = Field(description="Problem 5: taxi() or taxi(q_table).")
    find_qvalues: FindQvaluesConfig = Field(description="The lab-provided find_qvalues(env).")


class AssignmentFile(_Strict):
    """The TOML file as written (validation errors name `problems.<id>.<field>`)."""

    problems: ProblemTable = Field(description="One table per problem.")
    sandbox: SandboxConfig = Field(description="Resource limits of the sandbox.")


class AssignmentConfig(_Strict):
    """The whole assignment: one entry per problem plus the sandbox limits."""

    problems: dict[ProblemId, ProblemConfig] = Field(
        description="Every problem id (random_blackjack, blackjack, cartpole, car, taxi, find_qvalues)."
    )
    sandbox: SandboxConfig = Field(description="Resource limits of the sandbox.")

    @field_validator("problems")
    @classmethod
    def _every_problem(cls, problems: dict[ProblemId, ProblemConfig]) -> dict[ProblemId, ProblemConfig]:
        missing = [problem for problem in PROBLEM_IDS if problem not in problems]
        if missing:
            raise ValueError(f"expected settings for every problem; missing: {', '.join(missing)}")
        wrong = [
            problem for problem in PROBLEM_IDS if not isinstance(problems[problem], _PROBLEM_CLASSES[problem])
        ]
        if wrong:
            raise ValueError(f"expected each problem's own settings class; wrong for: {', '.join(wrong)}")
        return {problem: problems[problem] for problem in PROBLEM_IDS}

    @model_validator(mode="after")
    def _scoring(self) -> AssignmentConfig:
        if sum(problem.points for problem in self.problems.values() if problem.enabled) <= 0:
            raise ValueError("expected at least one enabled problem worth points; found none")
        return self

    @classmethod
    def from_file(cls, parsed: AssignmentFile) -> AssignmentConfig:
        """The configuration of a parsed file."""
        problems = {problem: getattr(parsed.problems, problem) for problem in PROBLEM_IDS}
        return cls(problems=problems, sandbox=parsed.sandbox)

    def problem(self, problem_id: ProblemId) -> ProblemConfig:
        """The settings of one problem."""
        return self.problems[problem_id]


def _describe(error: ValidationError, path: Path) -> str:
    lines = [f"{path}: invalid assignment configuration:"]
    for item in error.errors():
        location = ".".join(str(part) for part in item["loc"])
        if item["type"] == "missing":
            lines.append(f"  {location}: {item['msg']} (add it to the file)")
        else:
            lines.append(f"  {location}: {item['msg']} (found {item.get('input')!r})")
    lines.append("Fix these fields (every field is described in grader/assignment.toml).")
    return "\n".join(lines)


def load_config(path: Path | None = None) -> AssignmentConfig:
    """Load and validate the assignment configuration.

    Args:
        path: A TOML file; the bundled `grader/assignment.toml` when None.

    Returns:
        The validated configuration.

    Raises:
        ConfigError: The file is missing, not TOML, or a field is invalid (the message names the field,
            what was expected and what was found).
    """
    source = path or DEFAULT_CONFIG_PATH
    try:
        raw = tomllib.loads(source.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ConfigError(
            f"assignment configuration {source} not found: pass an existing TOML file"
        ) from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise ConfigError(f"{source} is not valid UTF-8 TOML ({error}): fix the syntax") from None
    try:
        return AssignmentConfig.from_file(AssignmentFile.model_validate(raw))
    except ValidationError as error:
        raise ConfigError(_describe(error, source)) from None
