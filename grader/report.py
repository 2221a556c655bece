"""The grade report: what a submission earned per problem, why, and how the grading ran.

In detail:

- `grader/report.py`: pydantic `Report` (`format`, `submission`, `sha256`, `seed`, `config_sha256`,
  `lab` (absent in older reports: `opengym`), `edition` (absent in older reports: `classic`),
  `gymnasium_version`, `grader_version`, `isolation`, `score`, `max_score`, `submission_error`, `problems`,
  `notebook`, `grader_errors`, `execution_time`, `timings`) and
  `ProblemResult` (`id`, `title`, `status`, `score`, `max_score`, `feedback`, `measurements`, `output`,
  `compat_events`, `seed`, `visibility`, `replay`, `timings`); a problem's run in a worker is a
  `ProblemRun(submission, result, isolation, internal_error)`. `ProblemRun.to_json()` is how a run crosses
  from an acceptance test (an xdist worker) to the controller (`grader.grading.plugin.outcome_json`): it never
  raises on student text (unencodable characters are replaced and that problem becomes `error`).
  `Report.isolation` / `ProblemRun.isolation` are an `IsolationSummary(full, layers: [LayerSummary(name,
  active, required, detail, remedy)], summary)` (`grader.grading.execution.isolation_summary`), or None when
  no sandbox ran, stored as `{}`; `ProblemResult.compat_events` are `CompatEventRecord`s
  (`grader.sandbox.outcome`). `ProblemResult.visibility` (`Visibility = Literal["visible", "after_due_date",
  "hidden"]`, Gradescope's words, default `visible`) comes from the problem's `visibility` in the assignment
  config and is set on every result (checked, rejected file, grader failure); the report itself always holds
  everything.
- `grader/report.py`: `withheld_ids(problems, shown)` and `errors_shown(grader_errors, withheld)` (pure),
  used by Gradescope's results and by `api/disclosure.report_view`, which, while a problem is withheld,
  also sets `score`, `execution_time` and `timings` to None. Student-visible views are tested byte for byte
  against reports that differ only in the withheld problem.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, JsonValue, WrapSerializer

from grader.sandbox.outcome import CompatEventRecord
from grader.sandbox.text import clean_plain
from grader.submission.notebook import NotebookSummary

Status = Literal["passed", "failed", "error", "timeout", "missing", "skipped"]
Visibility = Literal["visible", "after_due_date", "hidden"]
"""Who sees a problem's result and feedback (Gradescope's words): students at once, after the due date, or
only the instructor. The report always holds everything; the service's student views honour it."""

REPORT_FORMAT = 1
FIRST_EDITION = "classic"
"""The edition a report that names none was graded in: every report written before editions existed."""
FIRST_LAB = "opengym"
"""The lab a report that names none was graded in: every report written before the second lab existed."""
OUTPUT_CAP_CHARS = 8_000
"""Student output kept per problem in the report; the rest is replaced by a note saying how much was cut."""

TIMING_FIELDS: frozenset[str] = frozenset({"execution_time", "timings"})
"""Fields that measure time and so differ between runs; everything else is a function of (bytes, seed)."""


class Timings(BaseModel):
    """Where the wall time of a check (or of the whole grading) went. Differs between runs by nature."""

    model_config = ConfigDict(extra="forbid")

    wall_seconds: float = Field(description="Elapsed time from the start to the end of the check.")
    student_seconds: float = Field(description="Time spent inside the student's own functions.")
    overhead_seconds: float = Field(
        description="Everything else: sandbox start-up, import, data transfer, replay, judging."
    )


class GradingTimings(BaseModel):
    """Where a whole grading's time went. Differs between runs by nature."""

    model_config = ConfigDict(extra="forbid")

    elapsed_seconds: float = Field(description="Wall time from start to report (same as execution_time).")
    workers: int = Field(description="Parallel workers the checks ran on.")
    check_seconds: float = Field(
        description="Sum of the checks' wall times (what the workers were busy with)."
    )
    student_seconds: float = Field(description="Sum of the time spent inside the student's functions.")
    overhead_seconds: float = Field(
        description="check_seconds - student_seconds: sandbox start-up, import, transfer, replay, judging."
    )


class LayerSummary(BaseModel):
    """One layer of isolation and whether it protected the grading (`grader.sandbox.LayerReport`)."""

    model_config = ConfigDict(extra="forbid")

    name: str = Field(description="The layer: cgroup, bubblewrap, seccomp, privileges, rlimits, landlock.")
    active: bool = Field(description="Whether it was applied.")
    required: bool = Field(description="Whether full isolation needs it.")
    detail: str = Field(description="What it enforced, or why it could not.")
    remedy: str = Field(description="What would make it available; empty when nothing is needed.")


class IsolationSummary(BaseModel):
    """What the sandbox enforced for a grading (`grader.sandbox.IsolationReport`)."""

    model_config = ConfigDict(extra="forbid")

    full: bool = Field(description="Every required layer was active.")
    layers: list[LayerSummary] = Field(description="Each layer, active or not.")
    summary: str = Field(
        description="One line per layer: `[x] name: detail` or `[ ] name: detail -- remedy`."
    )


def _none_when_empty(value: object) -> object:
    return None if value == {} else value


Isolation = Annotated[
    IsolationSummary | None,
    BeforeValidator(_none_when_empty),
    WrapSerializer(lambda value, handler: {} if value is None else handler(value)),
]
"""An `IsolationSummary`, or None when no sandbox ran (the file was refused): `{}` in JSON, as always."""


class EpisodeReplay(BaseModel):
    """Enough to re-render one episode the student played: the game, its reset seed and the actions."""

    model_config = ConfigDict(extra="forbid")

    label: str = Field(description="Which episode this is, in words ('your shortest of 100 episodes').")
    env_id: str = Field(description="The gymnasium id the episode was played and replayed in.")
    reset_seed: int = Field(description="The seed the episode was reset with.")
    actions: list[int] = Field(description="The actions, in order, until the episode ended.")
    length: int = Field(description="Steps until the episode ended (as replayed).")
    total_reward: float = Field(description="Sum of the replayed rewards.")


class ProblemResult(BaseModel):
    """The verdict on one problem of one submission."""

    model_config = ConfigDict(extra="forbid")

    id: str = Field(description="Problem id, one of the registry's (grader/lab/problems.py lists the lab's).")
    title: str = Field(description="The problem's title in the lab.")
    status: Status = Field(
        description="passed, failed, error, timeout, missing, or skipped (not run: no verdict needed it)."
    )
    score: float = Field(description="Points earned.")
    max_score: float = Field(description="Points available.")
    feedback: str = Field(description="What was expected, what was measured, the likely cause.")
    measurements: dict[str, JsonValue] = Field(
        default_factory=dict, description="The numbers behind the verdict (deterministic for bytes + seed)."
    )
    output: str = Field(default="", description="The student's captured stdout/stderr, capped.")
    compat_events: list[CompatEventRecord] = Field(
        default_factory=list,
        description="What the lab-compatibility layer had to tolerate (e.g. steps after the episode ended).",
    )
    seed: int = Field(default=0, description="The sandbox seed this problem ran with.")
    visibility: Visibility = Field(
        default="visible",
        description="visible, after_due_date or hidden: when students may see this result (from the config).",
    )
    replay: EpisodeReplay | None = Field(
        default=None, description="The episode the HTML report animates (CartPole, MountainCar, Taxi)."
    )
    timings: Timings | None = Field(
        default=None, description="Where the check's time went (not deterministic)."
    )


class ProblemRun(BaseModel):
    """What one acceptance test hands to the controller: the result plus how it was isolated."""

    submission: str = Field(description="The submission path exactly as given to the plugin.")
    result: ProblemResult
    isolation: Isolation = Field(default=None, description="What the sandbox enforced.")
    internal_error: str | None = Field(
        default=None, description="'ExceptionType: message' when the grader itself failed on this problem."
    )

    @classmethod
    def grader_failure(
        cls,
        submission: str,
        problem: str,
        *,
        title: str,
        points: float,
        seed: int,
        detail: str,
        visibility: Visibility = "visible",
    ) -> ProblemRun:
        """The run of a problem the grader failed on: an ``error`` the student is told is not theirs."""
        result = ProblemResult(
            id=problem,
            title=title,
            status="error",
            score=0.0,
            max_score=points,
            feedback=f"The grader failed while checking this problem (not your code's fault): {detail}. "
            "Please report this to your instructor.",
            seed=seed,
            visibility=visibility,
        )
        return cls(submission=submission, result=result, internal_error=detail)

    def to_json(self) -> str:
        """This run as one JSON line, whatever strings the student's code put into it.

        Strings from the child are cleaned where they enter (`grader.sandbox`); should one still not
        encode (a lone surrogate, say), the run is written with every unencodable character replaced and
        the problem marked ``error`` with a note, instead of aborting the grading.
        """
        try:
            return self.model_dump_json()
        except ValueError as error:
            cleaned = ProblemRun.model_validate(clean_plain(self.model_dump(mode="python")))
            result = cleaned.result
            result.status = "error"
            result.score = 0.0
            result.feedback = (
                f"{result.feedback}\n\n"
                f"Your code's output or values held text that cannot be stored ({type(error).__name__}); "
                "unencodable characters were replaced and this problem scored 0. "
                "Print and return plain text only."
            )
            return cleaned.model_dump_json()


class InstructorOverride(BaseModel):
    """A score the instructor set, beside the machine's."""

    model_config = ConfigDict(extra="forbid")

    problem: str = Field(description="A problem id, or 'total' (the whole grade).")
    points: float = Field(description="The instructor's points.")
    machine: float | None = Field(description="What the machine gave (None: nothing was graded).")
    reason: str = Field(description="Why, in the instructor's words.")


class InstructorDecisions(BaseModel):
    """The instructor's last word on one student's grade (``gymgrade grade --overrides`` and ``[late]``);
    the machine's verdicts above it are unchanged."""

    model_config = ConfigDict(extra="forbid")

    student: str = Field(
        description="The student as the gradebook names them (a group's report has one each)."
    )
    overrides: list[InstructorOverride] = Field(default_factory=list, description="Scores set by hand.")
    late_penalty: float | None = Field(default=None, description="Points the late policy took (None: none).")
    late_note: str = Field(default="", description="How late, by which due time, and what was taken.")
    final_score: float | None = Field(description="The grade after the overrides and the late penalty.")


class Report(BaseModel):
    """The whole grade of one submission, serialised as the JSON the CLI prints and the service stores."""

    model_config = ConfigDict(extra="forbid")

    format: int = Field(default=REPORT_FORMAT, description="Version of this report layout.")
    submission: str = Field(description="The submission's file name (never a path).")
    sha256: str = Field(description="SHA-256 of the submission's bytes.")
    seed: int = Field(description="The grading seed; the same bytes and seed give the same verdicts.")
    config_sha256: str = Field(
        default="", description="SHA-256 of the assignment configuration that graded the file (its JSON)."
    )
    lab: str = Field(
        default=FIRST_LAB,
        description="The lab graded (grader/lab/labs.py: opengym, rl2). "
        "Absent in reports older than the second lab, all graded in the first, 'opengym'.",
    )
    edition: str = Field(
        default=FIRST_EDITION,
        description="The edition of the lab graded (grader/lab/editions/). "
        "Absent in reports older than editions, all graded in the first, 'classic'.",
    )
    edition_note: str | None = Field(
        default=None,
        description="Said to a file that looks written for an edition asking other problems than the one graded (the assignment's): "  # noqa: E501
        "which edition it shows and why; None otherwise.",
    )
    gymnasium_version: str = Field(description="Gymnasium version the episodes were replayed with.")
    grader_version: str = Field(description="gymgrade version.")
    isolation: Isolation = Field(default=None, description="What the sandbox could enforce for this grading.")
    score: float = Field(description="Points earned over all problems.")
    max_score: float = Field(description="Points available over all graded problems.")
    submission_error: str | None = Field(
        default=None, description="Why the file could not be graded at all (empty, not UTF-8, not Python...)."
    )
    problems: list[ProblemResult] = Field(default_factory=list, description="One result per graded problem.")
    notebook: NotebookSummary | None = Field(
        default=None,
        description="For a .ipynb submission: what ran at import and what was skipped, cell by cell.",
    )
    grader_errors: list[str] = Field(
        default_factory=list, description="Failures of the grader itself (not the student's); normally empty."
    )
    execution_time: float = Field(
        default=0.0, description="Wall time of the whole grading (not deterministic)."
    )
    timings: GradingTimings | None = Field(
        default=None, description="Where the grading's time went (not deterministic)."
    )
    instructor: list[InstructorDecisions] = Field(
        default_factory=list,
        description="The instructor's overrides and late penalty, per student (written into a class's reports by gymgrade grade; "  # noqa: E501
        "left out of the JSON when there are none).",
    )

    @property
    def full_marks(self) -> bool:
        """True when every graded problem passed (or was skipped: not run, worth nothing) and the file was
        gradable."""
        return self.submission_error is None and all(
            problem.status in ("passed", "skipped") for problem in self.problems
        )

    def to_json(self) -> str:
        """The report as indented JSON, fields in declaration order (stable for identical reports)."""
        return self.model_dump_json(indent=2, exclude=None if self.instructor else {"instructor"})

    def graded_view(self) -> dict[str, Any]:
        """The report without its timing fields and the instructor's decisions: identical for identical
        bytes and seed."""
        data = self.model_dump(exclude={*TIMING_FIELDS, "instructor"})
        for problem in data["problems"]:
            problem.pop("timings", None)
        return data


SHOWN_AT_ONCE: frozenset[str] = frozenset({"visible"})
"""The visibilities a student sees before the due date."""


def withheld_ids(problems: Sequence[Mapping[str, Any]], shown: frozenset[str]) -> frozenset[str]:
    """The ids of the problems a viewer who sees ``shown`` visibilities does not see (results as JSON data).

    Everything a student sees that sums or counts over problems (the total score, the grading's time, the
    grader's errors) must leave these out, or withhold itself with them: a total minus the shown parts is
    the withheld part.
    """
    return frozenset(
        str(problem.get("id"))
        for problem in problems
        if str(problem.get("visibility", "visible")) not in shown
    )


def errors_shown(grader_errors: Sequence[str], withheld: frozenset[str]) -> list[str]:
    """The grader's errors a viewer may read: those not about a withheld problem (``problem: ...``)."""
    return [error for error in grader_errors if error.split(":", 1)[0] not in withheld]


def plain_json(value: object) -> JsonValue:
    """Convert a measurement into JSON-safe data: numpy to Python, non-finite floats to strings.

    Args:
        value: A number, string, list, dict or numpy value produced by a check.

    Returns:
        The same data made of ``None``, ``bool``, ``int``, finite ``float``, ``str``, lists and dicts.

    Raises:
        TypeError: The value holds something that is not plain data (a check bug, not a student's).
    """
    if isinstance(value, np.ndarray):
        return plain_json(value.tolist())
    if isinstance(value, np.generic):
        return plain_json(value.item())
    if value is None or isinstance(value, bool | int | str):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else str(value)
    if isinstance(value, Mapping):
        return {str(key): plain_json(item) for key, item in value.items()}
    if isinstance(value, Sequence):
        return [plain_json(item) for item in value]
    raise TypeError(
        f"a measurement must be plain data (numbers, strings, lists, dicts); found {type(value).__name__}"
    )


def cap_output(text: str, limit: int = OUTPUT_CAP_CHARS) -> str:
    """Keep the start of a student's output and say how much was dropped."""
    if len(text) <= limit:
        return text
    return text[:limit] + f"\n[... {len(text) - limit} more characters of output not shown]"
