"""What a problem of an assignment is (`Problem`) and the ordered `Registry` all problem lists derive from.

A problem's declaration holds everything about it: its settings model, its check, the games it may be
played in, how the report chooses the episode it replays and how it plots its measurements. The lab's own
registry is `grader.lab.problems.PROBLEMS`; the edition packs (`grader.lab.editions`) build theirs from these
declarations. This module sits above the checks, the settings models, the games, the showcase rules and
the plots it refers to, and below the configuration loader (`grader.lab.assignment`), which it never imports:
a problem reads its settings from anything with a `problem(id)` method (`SettingsSource`).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Generic, Protocol, TypeVar

from grader.errors import PlanError, UnknownProblem
from grader.lab.ids import ProblemId, acceptance_module_name

if TYPE_CHECKING:
    from grader.lab.checks.base import ProblemCheck
    from grader.lab.games import Game
    from grader.lab.plots import Plotter
    from grader.lab.settings import ProblemConfig
    from grader.lab.showcase import ShowcaseRule

__all__ = ["Problem", "ProblemId", "Registry", "SettingsSource", "acceptance_module_name"]

ConfigT = TypeVar("ConfigT", bound="ProblemConfig")


class SettingsSource(Protocol):
    """What holds an assignment's settings by problem id (`grader.lab.assignment.AssignmentConfig` does)."""

    def problem(self, problem_id: ProblemId) -> ProblemConfig:
        """The settings of one problem."""
        ...


@dataclass(frozen=True)
class Problem(Generic[ConfigT]):
    """One problem, declared once: the configuration, `--only`, acceptance modules and reports derive from it.

    Attributes:
        id: The problem id (see `ProblemId`).
        title: Heading of the problem in reports; a configuration may override it per assignment.
        points: Points it is worth unless the configuration says otherwise (0: reported, not scored).
        config: The model of its `[problems.<id>]` table.
        check: Plans its calls and judges their outcomes, typed by `config`.
        enabled: Whether it is graded unless the configuration says otherwise. A problem disabled by default
            is optional: a configuration may omit its table (every field of `config` then needs a default).
        games: The games its episodes may be played in, the edition's own first (a configuration's
            `accepted_envs` chooses among them); empty for a problem whose calls play none.
        showcase: How the report chooses the episode it replays as an animation; None: no replay.
        plot: How the report plots its measurements; None: no plot.
    """

    id: ProblemId
    title: str
    points: float
    config: type[ConfigT]
    check: ProblemCheck[ConfigT]
    enabled: bool = True
    games: tuple[Game, ...] = field(default=(), hash=False)
    showcase: ShowcaseRule | None = None
    plot: Plotter | None = None

    @property
    def acceptance_module(self) -> str:
        """The name of its acceptance module in `grader/grading/cases/` (one test per submission)."""
        return acceptance_module_name(self.id)

    def table_defaults(self) -> dict[str, Any]:
        """The fields its configuration table takes from this declaration when the table leaves them out."""
        return {"title": self.title, "points": self.points, "enabled": self.enabled}

    def settings(self, assignment: SettingsSource) -> ConfigT:
        """This problem's settings in an assignment, typed: the one place a configuration is narrowed.

        Raises:
            PlanError: The assignment was loaded with another registry whose settings for this id are of
                another type.
        """
        found = assignment.problem(self.id)
        if not isinstance(found, self.config):
            raise PlanError(
                f"expected {self.config.__name__} settings for problem {self.id}, found "
                f"{type(found).__name__}: load the assignment with the registry that declares {self.id}"
            )
        return found


@dataclass(frozen=True)
class Registry:
    """The problems of an assignment in the order it poses them: the only list of problems.

    Raises:
        ValueError: Two problems share an id, or an id is not a Python identifier (a programming error,
            raised when the registry is built at import).
    """

    problems: tuple[Problem[Any], ...]

    def __post_init__(self) -> None:
        ids = [problem.id for problem in self.problems]
        repeated = sorted({problem for problem in ids if ids.count(problem) > 1})
        invalid = [problem for problem in ids if not problem.isidentifier()]
        if repeated or invalid or not ids:
            found = f"repeated {repeated}, invalid {invalid} in {ids}"
            raise ValueError(f"expected a non-empty registry of distinct identifiers; found {found}")

    def __iter__(self) -> Iterator[Problem[Any]]:
        return iter(self.problems)

    @property
    def ids(self) -> tuple[ProblemId, ...]:
        """Every problem id, in order."""
        return tuple(problem.id for problem in self.problems)

    def problem(self, problem_id: str) -> Problem[Any]:
        """The problem with this id.

        Raises:
            UnknownProblem: No problem has this id.
        """
        for problem in self.problems:
            if problem.id == problem_id:
                return problem
        raise UnknownProblem(self.unknown_message([problem_id]))

    def acceptance_problem(self, module_name: str) -> ProblemId:
        """The problem an acceptance module grades, from the module's name (`grader.grading.cases.test_<id>`).

        Raises:
            UnknownProblem: The module is no problem's acceptance module.
        """
        basename = module_name.rpartition(".")[2]
        for problem in self.problems:
            if problem.acceptance_module == basename:
                return problem.id
        raise UnknownProblem(
            f"acceptance module {basename} grades no problem: expected test_<id> for an id among "
            f"{', '.join(self.ids)}; declare the problem in grader/lab/problems.py or remove the module"
        )

    def select(self, names: Iterable[str]) -> tuple[ProblemId, ...]:
        """The named problems in registry order (what `--only` selects).

        Raises:
            UnknownProblem: A name is not a problem id, or no name is given.
        """
        chosen = [name.strip() for name in names if name.strip()]
        unknown = [name for name in chosen if name not in self.ids]
        if unknown or not chosen:
            raise UnknownProblem(self.unknown_message(unknown))
        return tuple(problem for problem in self.ids if problem in chosen)

    def unknown_message(self, unknown: Sequence[str]) -> str:
        """What a person reads for unknown problem ids: what was found and what is expected."""
        return f"unknown problem {', '.join(unknown) or '(none)'}; expected ids among {', '.join(self.ids)}"
