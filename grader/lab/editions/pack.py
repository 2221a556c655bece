"""The contract of an edition pack: what one published edition of a lab asks, declared once.

An assignment grades one edition. Its pack names the problems graded (a `Registry`: shared problems are the
declarations of `grader.lab.problems`, reused), every function the edition's template defines with its
parameters (stubs the student writes and functions the template provides), the games it plays, its
template, an honest reference solution in its API and its default assignment configuration. A later lab of
the course is more packs with their own `lab` (the second lab's are declared in `grader/lab/rl2/editions.py`)
and entries in `EDITIONS`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from grader.lab.registry import Registry

REPOSITORY = Path(__file__).resolve().parents[3]
"""The repository root: templates and reference solutions are repository files (submissions/)."""
PACKAGE = Path(__file__).resolve().parent
BUNDLED_CONFIG = PACKAGE.parent / "assignment.toml"

Api = Literal["classic", "gym026", "gymnasium"]


@dataclass(frozen=True)
class ExpectedFunction:
    """A function an edition's template defines.

    Attributes:
        name: Its name in the student's file.
        parameters: Its parameters, in order, as the template writes them (defaults included as text).
        provided: True when the template gives it complete (the student need not write it).
        env_ids: The environments it plays, as the edition names them.
    """

    name: str
    parameters: tuple[str, ...]
    provided: bool = False
    env_ids: tuple[str, ...] = ()

    @property
    def signature(self) -> str:
        """`name(p1, p2=...)` as the template writes it."""
        return f"{self.name}({', '.join(self.parameters)})"

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """The parameters' bare names (no defaults)."""
        return tuple(parameter.partition("=")[0].strip() for parameter in self.parameters)


@dataclass(frozen=True)
class Edition:
    """One published edition of a lab, graded as a pack.

    Attributes:
        name: Its id (`--edition NAME`, `edition = "NAME"` in an assignment configuration).
        number: Its place in the lab's history (1 = the first).
        title: What the course calls it.
        api: The gym API its template is written for.
        registry: The problems graded, in the order the edition poses them.
        functions: Every function its template defines (graded ones, provided ones, ungraded ones).
        template: Its template (stubs + provided functions), written from EDITIONS.md.
        reference: An honest complete solution in the edition's API.
        default_config: The assignment configuration used when none is given.
        notebook_name: The file name its template gives students.
        not_graded: Functions the edition asks for that this grader does not grade yet, each with why.
        lab: The lab it is an edition of: "opengym" (the OpenGym lab, "Reinforcement Learning 1" since
            2024: `grader.lab.editions`) or "rl2" ("Policy Function Iteration", "Reinforcement Learning 2"
            since 2024: `grader.lab.rl2`). Edition names are unique across labs; `number` counts within one.
    """

    name: str
    number: int
    title: str
    api: Api
    registry: Registry
    functions: tuple[ExpectedFunction, ...]
    template: Path
    reference: Path
    default_config: Path
    notebook_name: str
    not_graded: tuple[tuple[str, str], ...] = ()
    lab: str = "opengym"

    def function(self, name: str) -> ExpectedFunction | None:
        """The expected function with this name, or None."""
        return next((function for function in self.functions if function.name == name), None)
