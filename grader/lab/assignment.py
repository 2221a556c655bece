"""The assignment configuration: each registered problem's settings and the sandbox limits, loaded from TOML.

The file's shape derives from a `grader.lab.registry.Registry` (the lab's `grader.lab.problems.PROBLEMS`
unless told otherwise): one `[problems.<id>]` table per problem, parsed with the problem's own settings
model, whose `title`, `points` and `enabled` default to the registry's; a problem disabled by default may
be left out.

Which lab and edition a file grades (`configured_edition`): `edition = "NAME"`, else the current edition of
`lab = "NAME"`, else the first lab's first edition (`classic`: a file naming neither keeps its meaning); a
file naming both must name an edition of that lab (`grader.lab.labs.edition_in_lab` says what to write).
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from functools import cache, partial
from pathlib import Path
from typing import Annotated, Any

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    Field,
    PrivateAttr,
    SerializeAsAny,
    ValidationError,
    create_model,
    model_validator,
)

from grader.errors import ConfigError, UnknownProblem
from grader.lab.editions import DEFAULT_EDITION, EDITIONS, Edition, edition_of
from grader.lab.labs import edition_in_lab, lab_of
from grader.lab.problems import PROBLEMS
from grader.lab.registry import Problem, ProblemId, Registry
from grader.lab.settings import ProblemConfig, StrictModel
from grader.sandbox.limits import Limits

DEFAULT_CONFIG_PATH = Path(__file__).with_name("assignment.toml")
STUDENT_MODULES = ("tqdm", "matplotlib", "scipy", "pandas", "IPython")
"""What this course's students import in their own code (pyproject.toml's dependencies install them)."""


class SandboxConfig(StrictModel):
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
    student_modules: tuple[Annotated[str, Field(pattern=r"^[A-Za-z_]\w*$")], ...] = Field(
        default=STUDENT_MODULES,
        description="Top-level modules the course's students import besides the standard library, numpy and gym; "  # noqa: E501
        "`gymgrade doctor` checks that each one imports inside the sandbox.",
    )

    def to_limits(self, call_seconds: float) -> Limits:
        """The sandbox `Limits` for calls of one problem.

        Args:
            call_seconds: The problem's per-call wall-clock limit.
        """
        return Limits(call_seconds=call_seconds, **self.model_dump(exclude={"student_modules"}))


class AssignmentConfig(StrictModel):
    """The whole assignment: the settings of every problem of its registry, in order, and the sandbox limits.

    Made by `load_config`, which also records the registry it was loaded with (`registry`).
    """

    problems: dict[ProblemId, SerializeAsAny[ProblemConfig]] = Field(
        description="Each problem's settings (its own model), by id, in the registry's order."
    )
    sandbox: SandboxConfig = Field(description="Resource limits of the sandbox.")
    _registry: Registry = PrivateAttr(default=PROBLEMS)
    _edition: str = PrivateAttr(default=DEFAULT_EDITION)

    @model_validator(mode="after")
    def _scoring(self) -> AssignmentConfig:
        if sum(problem.points for problem in self.problems.values() if problem.enabled) <= 0:
            raise ValueError("expected at least one enabled problem worth points; found none")
        return self

    @property
    def registry(self) -> Registry:
        """The problems this configuration was loaded for (the lab's unless `load_config` was told)."""
        return self._registry

    @property
    def edition(self) -> str:
        """The edition this configuration grades (`edition = "..."`; the first edition when it names none)."""
        return self._edition

    @property
    def lab(self) -> str:
        """The lab of its edition (`grader.lab.labs.LABS`)."""
        return EDITIONS[self._edition].lab

    def problem(self, problem_id: ProblemId) -> ProblemConfig:
        """The settings of one problem; `registry.problem(problem_id).settings(self)` gives them typed.

        Raises:
            UnknownProblem: The id is not one of the registry's problems.
        """
        found = self.problems.get(problem_id)
        if found is None:
            raise UnknownProblem(self._registry.unknown_message([problem_id]))
        return found


def _with_defaults(problem: Problem[Any], table: object) -> object:
    return {**problem.table_defaults(), **table} if isinstance(table, dict) else table


def _bound(problem: Problem[Any], settings: ProblemConfig) -> ProblemConfig:
    return settings.for_problem(problem.id, problem.games)


def _table(problem: Problem[Any]) -> tuple[Any, Any]:
    """A problem's `[problems.<id>]` field: its settings model, the registry's defaults, bound to its id."""
    annotation: Any = Annotated[
        problem.config,
        BeforeValidator(partial(_with_defaults, problem)),
        AfterValidator(partial(_bound, problem)),
    ]
    description = f"{problem.title}. {problem.config.__doc__ or problem.config.__name__}"
    if problem.enabled:
        return annotation, Field(description=description)
    optional = f"{description} Optional (disabled unless its table says enabled = true)."
    return annotation, Field(default_factory=dict, validate_default=True, description=optional)


@cache
def assignment_file_model(registry: Registry) -> type[BaseModel]:
    """The model of an assignment TOML file for a registry (validation errors name `problems.<id>.<field>`).

    Args:
        registry: The problems the file configures.

    Returns:
        A model with `problems` (one field per problem, in order) and `sandbox`.
    """
    fields: dict[str, Any] = {problem.id: _table(problem) for problem in registry}
    tables = create_model(
        "ProblemTable",
        __base__=StrictModel,
        __doc__="The [problems.<id>] tables of the file, each parsed with its problem's settings.",
        **fields,
    )
    return create_model(
        "AssignmentFile",
        __base__=StrictModel,
        __doc__="The TOML file as written.",
        problems=(tables, Field(description="One table per problem.")),
        sandbox=(SandboxConfig, Field(description="Resource limits of the sandbox.")),
        late=(
            dict[str, Any] | None,
            Field(
                default=None,
                description="The late policy of the class's gradebooks (read by grader/classroom/late.py); "
                "no grading depends on it.",
            ),
        ),
        edition=(
            str,
            Field(
                default=DEFAULT_EDITION,
                description="The edition graded (grader/lab/editions/), else the lab's current edition when `lab` is named, else the first.",  # noqa: E501
            ),
        ),
        lab=(
            str | None,
            Field(
                default=None,
                description="The lab graded (grader/lab/labs.py: opengym, rl2); absent: the edition's lab (the first lab when no edition is named either).",  # noqa: E501
            ),
        ),
    )


def _describe(error: ValidationError, where: str) -> str:
    lines = [f"{where}: invalid assignment configuration:"]
    for item in error.errors():
        location = ".".join(str(part) for part in item["loc"])
        if item["type"] == "missing":
            lines.append(f"  {location}: {item['msg']} (add it to the file)")
        else:
            lines.append(f"  {location}: {item['msg']} (found {item.get('input')!r})")
    lines.append("Fix these fields (every field is described in grader/lab/assignment.toml).")
    return "\n".join(lines)


def read_config_file(source: Path) -> dict[str, Any]:
    """The TOML table of an assignment configuration file, not yet validated.

    Raises:
        ConfigError: The file is missing, cannot be read, or is not UTF-8 TOML.
    """
    try:
        return tomllib.loads(source.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ConfigError(
            f"assignment configuration {source} not found: pass an existing TOML file"
        ) from None
    except OSError as error:
        raise ConfigError(
            f"cannot read the assignment configuration {source} ({error.strerror or error}): "
            "pass a readable TOML file"
        ) from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise ConfigError(f"{source} is not valid UTF-8 TOML ({error}): fix the syntax") from None


def load_config(path: Path | None = None, registry: Registry | None = None) -> AssignmentConfig:
    """Load and validate the assignment configuration.

    Args:
        path: A TOML file; the bundled `grader/lab/assignment.toml` when None.
        registry: The problems it configures; by default those of the edition the file names
            (`edition = "..."`, the first edition when it names none).

    Returns:
        The validated configuration.

    Raises:
        ConfigError: The file is missing, not TOML, or a field is invalid (the message names the field,
            what was expected and what was found).
    """
    source = path or DEFAULT_CONFIG_PATH
    return config_from_data(read_config_file(source), where=str(source), registry=registry)


def config_from_data(
    data: Mapping[str, Any], *, where: str, registry: Registry | None = None
) -> AssignmentConfig:
    """The configuration that the data of an assignment file describes (a parsed TOML file, or
    `config_data` of a configuration: the same configuration again).

    Args:
        data: The file's tables: `edition`, `problems`, `sandbox`.
        where: Where the data comes from, for the error message (a file's path).
        registry: The problems it configures; by default those of the edition it names.

    Raises:
        ConfigError: A field is invalid (the message names the field, what was expected and what was found).
    """
    edition = configured_edition(data, where=where)
    if registry is None:
        registry = edition.registry
    try:
        parsed = dict(assignment_file_model(registry).model_validate(data))
        config = AssignmentConfig(problems=dict(parsed["problems"]), sandbox=parsed["sandbox"])
    except ValidationError as error:
        raise ConfigError(_describe(error, where)) from None
    config._registry = registry
    config._edition = edition.name
    return config


def configured_edition(data: Mapping[str, Any], *, where: str) -> Edition:
    """The edition an assignment file's data grades: `edition`, else `lab`'s current edition, else the
    first edition.

    Raises:
        UnknownEdition, UnknownLab: A name no pack or lab has.
        LabConflict: `edition` is not an edition of `lab` (the message says what to write).
    """
    named_edition, named_lab = data.get("edition"), data.get("lab")
    lab = None if named_lab is None else lab_of(named_lab, where=f"{where}: lab")
    if named_edition is None:
        return EDITIONS[DEFAULT_EDITION] if lab is None else lab.current_edition
    edition = edition_of(named_edition, where=f"{where}: edition")
    if lab is None:
        return edition
    return edition_in_lab(
        lab,
        edition,
        lab_named=f'{where}: lab = "{lab.name}"',
        edition_named=f'{where}: edition = "{edition.name}"',
        remedy=f'or write lab = "{edition.lab}", or leave lab out',
    )


def config_data(config: AssignmentConfig) -> dict[str, Any]:
    """A configuration as the plain (JSON) data of its file: `config_from_data` of it gives it back.

    This is how a grading's plan carries its configuration to the processes that check: as data read and
    validated once, not as a path each process reads again.
    """
    return {"edition": config.edition, **config.model_dump(mode="json")}
