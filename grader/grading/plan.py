"""What a grading covers, decided once: the validated assignment configuration and the problems selected.

A `GradingPlan` is made once, where a grading starts (`GradingPlan.load`: the TOML read and validated, the
selection checked), and travels as it is: to the acceptance session's workers as data (`to_data`, decoded
by `from_data` with the same models), never as a path each process reads again. So every process of a
grading checks with the configuration whose digest (`config_sha256`) its reports record.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

from grader.errors import UnknownProblem
from grader.lab.assignment import AssignmentConfig, config_data, config_from_data, load_config
from grader.lab.registry import ProblemId, Registry
from grader.report import Visibility


@dataclass(frozen=True)
class GradingPlan:
    """The problems one grading covers and the configuration that scores them.

    Attributes:
        assignment: The validated configuration (its registry is the edition's problems).
        problems: The problems graded, in the registry's order: the enabled ones, or a selection of them.
        config: The file the configuration was read from; None for the bundled one.
    """

    assignment: AssignmentConfig
    problems: tuple[ProblemId, ...]
    config: Path | None = None

    @classmethod
    def load(cls, config: Path | None, only: Sequence[str] | None) -> GradingPlan:
        """The enabled problems (restricted to ``only``) of an assignment configuration file.

        Raises:
            grader.errors.UnknownProblem: ``only`` names a problem the configuration's edition lacks.
            grader.errors.ConfigError: The configuration is invalid.
        """
        return cls.of(load_config(config), only, config=config)

    @classmethod
    def of(
        cls, assignment: AssignmentConfig, only: Sequence[str] | None = None, *, config: Path | None = None
    ) -> GradingPlan:
        """The enabled problems (restricted to ``only``) of a loaded configuration.

        Raises:
            grader.errors.UnknownProblem: ``only`` names a problem the configuration's edition lacks.
        """
        registry = assignment.registry
        unknown = sorted(set(only or ()) - set(registry.ids))
        if unknown:
            raise UnknownProblem(registry.unknown_message(unknown))
        problems = tuple(
            problem
            for problem in registry.ids
            if assignment.problem(problem).enabled and (not only or problem in only)
        )
        return cls(assignment=assignment, problems=problems, config=config)

    @property
    def registry(self) -> Registry:
        """The edition's problems (the configuration's registry)."""
        return self.assignment.registry

    @property
    def edition(self) -> str:
        """The edition the configuration grades."""
        return self.assignment.edition

    @cached_property
    def config_sha256(self) -> str:
        """SHA-256 of the configuration's validated JSON form: a report records it, so a resumed batch
        knows which configuration graded a file."""
        return hashlib.sha256(self.assignment.model_dump_json().encode()).hexdigest()

    @cached_property
    def points(self) -> dict[ProblemId, float]:
        """Each graded problem's points."""
        return {problem: self.assignment.problem(problem).points for problem in self.problems}

    @cached_property
    def titles(self) -> dict[ProblemId, str]:
        """Each graded problem's title."""
        return {problem: self.assignment.problem(problem).title for problem in self.problems}

    @cached_property
    def visibility(self) -> dict[ProblemId, Visibility]:
        """When each graded problem's result is shown to the student."""
        return {problem: self.assignment.problem(problem).visibility for problem in self.problems}

    def to_data(self) -> dict[str, Any]:
        """This plan as plain JSON data (the configuration's file tables, the problems, the file's path)."""
        return {
            "assignment": config_data(self.assignment),
            "problems": list(self.problems),
            "config": str(self.config) if self.config is not None else None,
        }

    @classmethod
    def from_data(cls, data: Mapping[str, Any]) -> GradingPlan:
        """The plan `to_data` gave (its configuration decoded with the models that validated it).

        Raises:
            grader.errors.ConfigError: The data is not a configuration (data `to_data` made always is).
        """
        config = Path(data["config"]) if data.get("config") else None
        assignment = config_from_data(data["assignment"], where=str(config or "the grading's plan"))
        return cls(assignment=assignment, problems=tuple(data["problems"]), config=config)
