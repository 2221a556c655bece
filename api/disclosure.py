"""What a caller may see of a graded submission: everything (the instructor) or the student's view.

Students never see a grading seed (the submission's, the report's or a problem's) unless the instructor
releases them (GYMGRADE_RELEASE_SEEDS), because every start of every call follows from it through public
functions. A problem marked ``hidden`` in the assignment config, or ``after_due_date`` before
GYMGRADE_DUE_DATE, is withheld: its status, score, feedback, measurements, output, events and timings are
replaced by a note. So is everything summed over the problems, which would give the withheld ones away
(a total minus the shown parts is the withheld part): the total score, the grading's time and its timings,
and the grader's errors about a withheld problem. The stored report always keeps everything; these pure
functions only shape the views.

In detail:

  precision of the learner's cells (`recompute(..., precision=)`): a table whose every cell is a float32
  number is recomputed with `np.float32` cells, so NumPy rounds every update as it did in the child, and is
  compared within `float32_table_tolerance`; any other table in float64 within `table_tolerance`. A later
  learner (Q-learning, Expected SARSA, the MDP lab's iterations) adds a rule and a check on the same core.

- Seeds: `SEED_POLICY=random` (default) stores `held_out_seed(2**31)` in each submission's row (the
  column is a 32-bit integer); `fixed` uses `SEED` and is refused with the practice seed 0 outside
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import UTC, datetime
from typing import Any

from api.auth import Principal
from api.courses import due_date_of
from api.models import Assignment
from grader.report import errors_shown, withheld_ids

JsonObject = dict[str, Any]

WITHHELD = "withheld"
"""The status a student sees for a withheld problem."""

EVERY_VISIBILITY = frozenset({"visible", "after_due_date", "hidden"})


@dataclass(frozen=True)
class Disclosure:
    """What one caller may see.

    Attributes:
        seeds: The grading seed and the per-problem seeds are shown.
        shown: The problem visibilities whose results are shown.
        due_date: The assignment's due date (for the note on ``after_due_date`` problems), if set.
    """

    seeds: bool
    shown: frozenset[str]
    due_date: datetime | None = None

    @property
    def everything(self) -> bool:
        """True when every problem is shown, whatever its visibility (the staff's view)."""
        return self.shown >= EVERY_VISIBILITY

    def shows(self, problem: JsonObject) -> bool:
        """True when the problem's result may be shown (reports without visibility are visible)."""
        return str(problem.get("visibility", "visible")) in self.shown


FULL = Disclosure(seeds=True, shown=EVERY_VISIBILITY)
"""The instructor's view: everything."""


def disclosure_for(caller: Principal, assignment: Assignment, now: datetime | None = None) -> Disclosure:
    """What ``caller`` may see now of the assignment's reports.

    Args:
        caller: The staff or a student.
        assignment: Whether it releases seeds, and its due date (the default assignment's are
            GYMGRADE_RELEASE_SEEDS and GYMGRADE_DUE_DATE).
        now: The current time (aware); the clock when None.
    """
    if caller.is_instructor:
        return FULL
    moment = now or datetime.now(UTC)
    due = due_date_of(assignment)
    shown = {"visible"} | ({"after_due_date"} if due is not None and moment >= due else set())
    return Disclosure(seeds=assignment.release_seeds, shown=frozenset(shown), due_date=due)


def problem_view(problem: JsonObject, disclosure: Disclosure) -> JsonObject:
    """One problem's result as ``disclosure`` allows (a copy; the stored result is not changed)."""
    view = dict(problem)
    if not disclosure.seeds:
        view["seed"] = None
    if disclosure.shows(problem):
        return view
    view.update(
        status=WITHHELD,
        score=None,
        feedback=_withheld_note(str(problem.get("visibility")), disclosure.due_date),
        measurements={},
        output="",
        compat_events=[],
        timings=None,
        replay=None,
    )
    return view


def report_view(report: JsonObject, disclosure: Disclosure) -> JsonObject:
    """A report as ``disclosure`` allows: seeds and withheld problems replaced, and with them every total.

    While a problem is withheld, the total score, the grading's time (``execution_time``, ``timings``) and
    the grader's errors about the withheld problem are left out: what remains is the same whatever the
    withheld problem's outcome.
    """
    view = dict(report)
    problems = report.get("problems", [])
    view["problems"] = [problem_view(problem, disclosure) for problem in problems]
    if not disclosure.seeds:
        view["seed"] = None
    withheld = withheld_ids(problems, disclosure.shown)
    if withheld:
        view.update(score=None, execution_time=None, timings=None)
        view["grader_errors"] = errors_shown(report.get("grader_errors", []), withheld)
    return view


def withholds_any(report: JsonObject | None, disclosure: Disclosure) -> bool:
    """True when ``disclosure`` withholds some problem of ``report`` (so also its total score)."""
    if disclosure.everything:
        return False
    problems = report.get("problems", []) if report else []
    return any(not disclosure.shows(problem) for problem in problems)


def _withheld_note(visibility: str, due_date: datetime | None) -> str:
    if visibility == "after_due_date":
        when = f"{due_date:%Y-%m-%d %H:%M} UTC" if due_date is not None else "a date your instructor sets"
        return (
            f"This problem's result is shown after the due date ({when}); your instructor already sees it. "
            "The total score is shown then too."
        )
    return (
        "This problem's result is hidden from students (your instructor sees it); "
        "the total score is hidden with it."
    )
