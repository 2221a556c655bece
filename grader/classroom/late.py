"""The late policy of the assignment configuration's ``[late]`` table, and the penalty it gives a submission.

::

    [late]
    due = 2026-03-01T23:59:00-05:00   # ISO 8601 with its zone (a TOML date-time or a string)
    penalty_per_day = 0.1              # share of the assignment's maximum, per day or part of a day late
    max_penalty = 0.5                  # the same share, the most ever taken
    grace_minutes = 15                 # submissions up to 15 minutes after the due time are on time

    [late.extensions]
    alice = 2026-03-04T23:59:00-05:00  # a student's own due time (the gradebook's student id)

A submission at or before its due time plus the grace is on time. Past it, every started day counts from
the due time itself (the grace forgives; it does not move the clock): 1 second past the grace is one day,
24 hours and 1 second is two. The penalty is ``min(days * penalty_per_day, max_penalty) * max_score`` points,
shown as its own number and never folded into a problem's score. A time without a zone (Blackboard's file
names, a spreadsheet) is read in the due time's zone.

The policy changes no grading: it is read beside the configuration, not part of the digest reports record,
so changing it rewrites the gradebooks and regrades nobody.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from datetime import datetime, timedelta
from pathlib import Path
from typing import Any

from pydantic import AwareDatetime, BaseModel, ConfigDict, Field, ValidationError

from grader.classroom.errors import LatePolicyError
from grader.lab.assignment import DEFAULT_CONFIG_PATH, read_config_file

DAY = timedelta(days=1)
LATE_TABLE = "late"


class LatePolicy(BaseModel):
    """The ``[late]`` table (see the module docstring)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    due: AwareDatetime = Field(description="The due time, ISO 8601 with its time zone.")
    penalty_per_day: float = Field(
        ge=0.0, le=1.0, description="Share of the assignment's maximum taken per day or part of a day late."
    )
    max_penalty: float = Field(default=1.0, ge=0.0, le=1.0, description="The most ever taken, as that share.")
    grace_minutes: float = Field(
        default=0.0, ge=0.0, le=7 * 24 * 60, description="Minutes after the due time still on time."
    )
    extensions: dict[str, AwareDatetime] = Field(
        default_factory=dict, description="A student's own due time, by the gradebook's student id."
    )

    def due_for(self, student: str) -> datetime:
        """The due time of ``student``: their extension, else the class's."""
        return self.extensions.get(student, self.due)


@dataclass(frozen=True)
class Lateness:
    """What the policy makes of one student's submission.

    Attributes:
        due: Their due time (an extension's when they have one).
        extended: Whether ``due`` is an extension.
        submitted_at: When they submitted (None: the source does not say).
        days: Days or parts of a day charged (0: on time, or nothing known to charge).
        penalty: Points taken from their total.
        note: What a person should know ("2 days late", "hours unknown: ...") ("" when on time).
    """

    due: datetime
    extended: bool
    submitted_at: datetime | None
    days: int
    penalty: float
    note: str = ""


def late_policy_of(data: Mapping[str, Any], *, where: str) -> LatePolicy | None:
    """The late policy of a configuration file's tables (None when it has no ``[late]``).

    Raises:
        LatePolicyError: The table is not as the module docstring says (the message names each field).
    """
    table = data.get(LATE_TABLE)
    if table is None:
        return None
    try:
        return LatePolicy.model_validate(table)
    except ValidationError as error:
        lines = [f"{where}: invalid [{LATE_TABLE}] table:"]
        for item in error.errors():
            location = ".".join(str(part) for part in item["loc"]) or LATE_TABLE
            lines.append(f"  {LATE_TABLE}.{location}: {item['msg']} (found {item.get('input')!r})")
        lines.append(
            "Write due as an ISO 8601 time with its zone (2026-03-01T23:59:00-05:00) and the penalties as shares between 0 and 1 (0.1 is a tenth of the assignment's maximum)."  # noqa: E501
        )
        raise LatePolicyError("\n".join(lines)) from None


def read_late_policy(config: Path | None) -> LatePolicy | None:
    """The late policy of an assignment configuration file (the bundled one when None), None without one.

    Raises:
        grader.errors.ConfigError: The file cannot be read as TOML.
        LatePolicyError: Its ``[late]`` table is invalid.
    """
    source = config or DEFAULT_CONFIG_PATH
    return late_policy_of(read_config_file(source), where=str(source))


def in_zone_of(moment: datetime, reference: datetime) -> datetime:
    """``moment`` with a zone: its own, else ``reference``'s (a time a source gives without a zone)."""
    return moment if moment.tzinfo is not None else moment.replace(tzinfo=reference.tzinfo)


def lateness(
    policy: LatePolicy,
    student: str,
    *,
    submitted_at: datetime | None,
    marked_late: bool | None,
    max_score: float,
) -> Lateness:
    """The penalty of one submission under ``policy``: a pure function of its time.

    Args:
        policy: The late policy.
        student: The student as the gradebook names them (their extension is looked up by it).
        submitted_at: When they submitted (None: unknown).
        marked_late: Whether the source marks it late (Canvas's ``LATE``); used only when the time is unknown.
        max_score: The assignment's maximum (the shares are of it).

    Returns:
        The due time that applies, the days charged and the penalty in points (rounded to 1e-9).
    """
    due = policy.due_for(student)
    extended = student in policy.extensions
    grace = timedelta(minutes=policy.grace_minutes)
    if submitted_at is None:
        if not marked_late:
            return Lateness(due, extended, None, 0, 0.0)
        if extended:
            return Lateness(
                due,
                extended,
                None,
                0,
                0.0,
                f"marked late by the download, but their due time is extended to {due.isoformat()} and the hours are unknown: "  # noqa: E501
                "no penalty taken; give the time with --submitted-at FILE",
            )
        return Lateness(
            due,
            extended,
            None,
            1,
            _points(1, policy, max_score),
            "marked late by the download, the hours unknown: charged one day, the least a late mark means; "
            "give the time with --submitted-at FILE (or a Canvas submissions CSV) for the policy's count",
        )
    moment = in_zone_of(submitted_at, due)
    past = moment - due
    if past <= grace:
        return Lateness(due, extended, moment, 0, 0.0)
    days = math.ceil(past / DAY)
    penalty = _points(days, policy, max_score)
    capped = " (the policy's cap)" if days * policy.penalty_per_day > policy.max_penalty else ""
    return Lateness(
        due,
        extended,
        moment,
        days,
        penalty,
        f"{days} day{'s' if days != 1 else ''} late (submitted {moment.isoformat()}, due {due.isoformat()}{', extended' if extended else ''}): {penalty:g} points taken{capped}",  # noqa: E501
    )


def _points(days: int, policy: LatePolicy, max_score: float) -> float:
    share = min(days * policy.penalty_per_day, policy.max_penalty)
    return round(share * max_score, 9)
