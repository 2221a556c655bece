"""What the cells call of `compare()` returned, read defensively: the tables the judge may find played.

The cells call's value comes from the student's process (`grader.sandbox.child.cells`). Bound
(`bound_tables_of`), it names which of the grader's tables the child bound to which globals; the tables are
taken from the plan, never from the child. Otherwise (`cells_value`) it lists the Taxi tables the
notebook's cells left, labelled by the learner call that made them, each validated (shape, finite numbers).
The feedback's first words come from here too: what was bound to what (`bound_preface`) or why the cells ran
instead (`fallback_preface`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from grader.lab.checks.compare_tables import LEARNERS
from grader.sandbox.outcome import PlainValue
from grader.submission.notebook.cells import SCRIPT_CELL


@dataclass(frozen=True)
class NotebookTable:
    """A Taxi Q-table the notebook's cells left behind (untrusted values, validated shape)."""

    names: tuple[str, ...]
    learner: str | None
    decay: bool | None
    episodes: int | None
    table: npt.NDArray[np.float64]
    bound: bool = False
    """The grader's table, bound in place of the learner call (else one the notebook's cells made)."""

    @property
    def label(self) -> str:
        """How the feedback names it: its globals and the learner call that made it."""
        name = " / ".join(f"`{name}`" for name in self.names) or "a table"
        if self.learner is None:
            return name
        made = [
            f"decay={self.decay}" if self.decay is not None else "",
            f"N={self.episodes}" if self.episodes else "",
        ]
        call = f"{self.learner}({', '.join(filter(None, made))})"
        return f"{name} (bound for {call})" if self.bound else f"{name} (from {call})"


MAX_NAME_CHARS = 60
"""A global's name as the child reported it, cut to this length for the feedback."""


MAX_STATEMENT_CHARS = 120
"""A training statement as the child quoted it, cut to this length for the feedback."""


@dataclass(frozen=True)
class BoundTable(NotebookTable):
    """A table of the grader's bound to globals the notebook's training would set."""

    read: tuple[str, ...] = ()
    """The names compare() reads (the others were bound because a training statement sets them)."""
    where: tuple[tuple[str, int, str], ...] = ()
    """(name, cell, statement) of the training statements that set its names."""


def bound_tables_of(value: PlainValue, planned: PlainValue) -> list[NotebookTable] | None:
    """The grader's tables as the child bound them (None: nothing bound, the cells ran).

    The tables are the plan's own (`planned`, never the child's); the child says only which names it bound
    to which learner's table, which the feedback reports and which orders the expected means.
    """
    if (
        not isinstance(value, dict)
        or not isinstance(value.get("bound"), list)
        or not isinstance(planned, dict)
    ):
        return None
    groups: dict[tuple[str, str], dict[str, Any]] = {}
    for entry in value["bound"]:
        if (
            not isinstance(entry, dict)
            or entry.get("learner") not in LEARNERS
            or not isinstance(entry.get("name"), str)
        ):
            continue
        decay = entry.get("decay") if type(entry.get("decay")) is bool else None
        key = (str(entry["learner"]), "constant" if decay is False else "decay")
        group = groups.setdefault(key, {"names": [], "read": [], "decay": decay, "N": None, "where": []})
        name = entry["name"][:MAX_NAME_CHARS]
        group["names"].append(name)
        if entry.get("read") is True:
            group["read"].append(name)
        if type(entry.get("N")) is int and group["N"] is None:
            group["N"] = entry["N"]
        statement, cell = entry.get("statement"), entry.get("cell")
        if isinstance(statement, str) and type(cell) is int:
            group["where"].append((name, cell, statement[:MAX_STATEMENT_CHARS]))
    tables: list[NotebookTable] = []
    for (learner, schedule), group in groups.items():
        table = planned.get(learner, {}).get(schedule) if isinstance(planned.get(learner), dict) else None
        if table is None:
            continue
        tables.append(
            BoundTable(
                names=tuple(group["names"][:5]),
                learner=learner,
                decay=group["decay"],
                episodes=group["N"],
                table=np.asarray(table, dtype=np.float64),
                bound=True,
                read=tuple(group["read"]),
                where=tuple(group["where"]),
            )
        )
    return tables or None


_LEARNER_NAMES = {"qlearn": "Q-learning", "sarsa0": "SARSA"}


def bound_preface(tables: Sequence[NotebookTable]) -> str:
    parts = []
    for table in tables:
        if not isinstance(table, BoundTable) or not table.read:
            continue
        schedule = "constant-epsilon " if table.decay is False else ""
        names = " and ".join(f"`{name}`" for name in table.read)
        statements = [
            f"`{statement}` in {_cell(cell)}" for name, cell, statement in table.where if name in table.read
        ]
        source = f"as your {statements[0]} sets it" if statements else "by its name"
        parts.append(f"{names} <- the {schedule}{_LEARNER_NAMES[table.learner or 'qlearn']} table ({source})")
    bound = "; ".join(parts)
    return f"Bound the grader's own Taxi tables (drawn from the grading seed, exact greedy returns known) to the globals compare() reads instead of running your training, since compare()'s verdict does not depend on what training learns: {bound}; then called compare()"  # noqa: E501


def _cell(cell: int) -> str:
    return "your file" if cell == SCRIPT_CELL else f"cell {cell}"


def fallback_preface(value: PlainValue) -> str:
    reason = value.get("fallback") if isinstance(value, dict) else None
    if not isinstance(reason, str):
        return ""
    return f"The grader's tables could not stand in for your training: {reason[:300]}. "


def cells_value(value: PlainValue) -> tuple[list[int], list[NotebookTable]]:
    """The cells call's value, validated (it comes from the student's process): the numbers of the cells
    that ran (their seconds are the problem's timings, not the verdict's) and the tables they left."""
    ran: list[int] = []
    tables: list[NotebookTable] = []
    if not isinstance(value, dict):
        return ran, tables
    for entry in value.get("cells", []) if isinstance(value.get("cells"), list) else []:
        if isinstance(entry, dict) and type(entry.get("cell")) is int:
            ran.append(entry["cell"])
    for entry in value.get("tables", []) if isinstance(value.get("tables"), list) else []:
        if not isinstance(entry, dict):
            continue
        table = np.asarray(entry.get("table"), dtype=object)
        if table.shape != (500, 6):
            continue
        try:
            numbers = np.asarray(table, dtype=np.float64)
        except (TypeError, ValueError):
            continue
        if not np.all(np.isfinite(numbers)):
            continue
        names = entry.get("names")
        learner, decay, episodes = entry.get("learner"), entry.get("decay"), entry.get("N")
        tables.append(
            NotebookTable(
                names=tuple(str(name)[:60] for name in names[:5]) if isinstance(names, list) else (),
                learner=learner if learner in ("qlearn", "sarsa0") else None,
                decay=decay if type(decay) is bool else None,
                episodes=episodes if type(episodes) is int else None,
                table=numbers,
            )
        )
    return ran, tables
