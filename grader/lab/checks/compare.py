"""Edition rl1, problem 7: `compare()` plays the notebook's Q-learning and SARSA tables greedily.

`compare()` takes no arguments: it reads the tables the notebook's training cells would leave in its globals.
Its verdict does not depend on what the training learned: the judge finds, for each half of compare()'s
replayed episodes, the table whose greedy actions they all are (a row's maximisers), so the episodes reveal
which tables were played; the returned pair must be the two replayed means, Q-learning's first, and each mean
must lie within its z-test tolerance of the exact greedy return of the table its episodes reveal
(`reference.oracles`). So by default (`bind_tables`) no training runs:

- **Bound** (the default): the plan's cells call carries the grader's tables (`compare_tables.bound_tables`,
  drawn from the problem's seed: tie-free, every start delivered, each pair of tables told apart by their
  greedy routes), one per learner and epsilon schedule. In the child, `grader.sandbox.child.binding` binds
  them to the globals compare() reads (its code's `LOAD_GLOBAL`s, through the module's functions it calls),
  Q-learning's and SARSA's told apart by the file's own `qlearn(...)`/`sarsa0(...)` statements, then by the
  names, and runs no cell. The judge takes the tables from its own plan, never from the child; the child says
  only which names it bound to which (the feedback quotes it).
- **Cells** (the fallback where binding cannot serve, said in the feedback; or every time with
  `bind_tables = false`): the notebook's code cells run in the sandbox first (one unrecorded call with its
  own time limit, `cells_seconds`; `grader.sandbox.child.cells`), which returns every Taxi Q-table they left
  behind, labelled with the learner that made it; those are the tables the episodes may reveal.

`run_cells = false` turns the problem off: compare() is `skipped`, worth 0 points, with a note saying why.

The data flows in one chain:

- `grader.submission.notebook.building` keeps, besides the graded module, every code cell Run All would run,
  as IPython reads it (`NotebookModule.cells`, computed in the bounded reader);
  `grader.grading.grade._prepare` writes them beside the module
  (`grader.submission.notebook.cells.write_cells`).
- A check plans `Call(RUN_CELLS, seconds=...)` (its own wall-clock limit) before its own calls;
  `grader.grading.execution.run_problem` fills in the argument (`runnable_cells`: the notebook's cells, a
  `.py` export's cells, or a plain `.py` module whole as a script) because only it knows the submission.
  The binding reads the same cells (never runs them) for the training statements.
- In the child, `grader.sandbox.child.calls` runs a `RUN_CELLS` call with
  `grader.sandbox.child.cells.run_cells`: bound, its value names what was bound; else the cells run in the
  module's globals (the same child then serves the problem's calls), the first failing cell raises
  `NotebookCellError` (the outcome is an exception, so the run stops there; the message says why the cells
  ran), and the value is plain data: each cell's time and the Taxi Q-tables left behind, labelled by learner,
  with why nothing was bound.
- The check judges with that value and the replayed episodes of its own calls (`grader.lab.checks.compare`);
  its result carries the `ran_notebook_cells` measurement (the globals were set, bound or by the cells), so
  `with_notebook` adds no "global only a skipped statement sets" note to it. Cells that left no table and a
  compare() that then raises is `failed`, saying where a `.py` (under `if __name__ == "__main__":`) or a
  notebook trains the tables; a file that did not import within `import_seconds` (training at its top level)
  is `timeout` with the runner's message (`grader.sandbox.outcome.IMPORT_TIMEOUT`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from pydantic import Field, model_validator

from grader.lab.checks.base import CallRecord, Verdict, outcome_verdict, paused_gc
from grader.lab.checks.compare_tables import bound_tables
from grader.lab.checks.compare_values import (
    NotebookTable,
    bound_preface,
    bound_tables_of,
    cells_value,
    fallback_preface,
)
from grader.lab.checks.episodes import Episode, played_episodes
from grader.lab.checks.integrity import NO_EPISODES, games_budget, integrity_problem
from grader.lab.checks.taxi import EPISODE_STEPS
from grader.lab.checks.values import as_number, describe
from grader.lab.settings import PlayedProblemConfig, Probability
from grader.lab.stats import mean_tolerance
from grader.sandbox.outcome import IMPORT_TIMEOUT, RUN_CELLS, Call, FunctionInfo, OutcomeStatus, PlainValue
from grader.submission.notebook.cells import RAN_CELLS, SCRIPT_CELL
from reference.oracles import greedy_policy_return

RETURN_TOLERANCE = 1e-6
"""How far a returned mean may be from its replayed episodes' mean (float rounding of a sum of 1 000)."""
RANDOM_SHARE = 0.25
"""More non-greedy actions than this share of a half's steps reads as random play."""
NOT_GRADABLE = (
    "Not graded: compare() takes no arguments and reads the tables your notebook's own training cells made; this assignment does not grade it, so it is worth 0 points. "  # noqa: E501
    "Instructors: this assignment's [problems.compare] says run_cells = false; the default, run_cells = true, binds the grader's tables to the globals compare() reads (or runs the notebook's cells in the sandbox where that cannot serve) before calling compare() (docs/editions.md)."  # noqa: E501
)


class CompareConfig(PlayedProblemConfig):
    """The settings of `compare()` (edition rl1)."""

    run_cells: bool = Field(
        default=True,
        description="Grade compare() (the default): its tables bound (`bind_tables`) or the notebook's code cells run in the sandbox (in order, as Run All does) before calling it; "  # noqa: E501
        "false turns it off: compare() is skipped and worth 0 points whatever `points` says.",
    )
    bind_tables: bool = Field(
        default=True,
        description="Bind the grader's own tables (seeded, exact greedy returns known) to the globals compare() reads instead of running the training cells (the default: seconds); "  # noqa: E501
        "the cells still run where binding cannot serve a compare() (the feedback says why). false runs every cell, as Run All does.",  # noqa: E501
    )
    cells_seconds: float = Field(
        default=1800.0,
        gt=0.0,
        description="Wall-clock limit of running the cells (their training runs included); call_seconds bounds compare() itself. "  # noqa: E501
        "The lab's cells take about 7 minutes of CPU; the limit leaves room for a machine shared with other gradings.",  # noqa: E501
    )
    episodes_per_table: int = Field(
        default=1000,
        ge=1,
        description="Greedy episodes compare() must play with each table (the lab's 1 000).",
    )
    mean_alpha: Probability = Field(
        default=1e-6,
        description="False-fail probability of EACH two-sided z-test of a replayed mean against its table's exact greedy return.",  # noqa: E501
    )

    @model_validator(mode="before")
    @classmethod
    def _not_gradable_is_worth_nothing(cls, data: Any) -> Any:
        if isinstance(data, dict) and not data.get("run_cells", True):
            return {**data, "points": 0.0}
        return data


@dataclass(frozen=True)
class CompareCheck:
    """The notebook's cells, then compare(): both halves replayed, greedy on notebook tables, exact means."""

    def plan(self, settings: CompareConfig, functions: Mapping[str, FunctionInfo], seed: int) -> list[Call]:
        """The cells call (own time limit, unrecorded; with the grader's tables to bind when `bind_tables`),
        then a recorded compare(); none without run_cells."""
        if not settings.run_cells:
            return []
        budget = games_budget(2 * settings.episodes_per_table, EPISODE_STEPS)
        kwargs: dict[str, PlainValue] = {"then": "compare"}
        if settings.bind_tables:
            kwargs["bind"] = bound_tables(seed)
        return [
            Call(
                RUN_CELLS,
                kwargs=kwargs,
                record_episodes=False,
                budget=NO_EPISODES,
                seconds=settings.cells_seconds,
            ),
            Call("compare", budget=budget),
        ]

    @paused_gc
    def judge(self, settings: CompareConfig, records: Sequence[CallRecord]) -> Verdict:
        """Judge compare()'s pair against its replayed episodes and its tables' exact greedy returns."""
        if not settings.run_cells:
            return Verdict("skipped", 0.0, NOT_GRADABLE, {"run_cells": False})
        verdict = _judge_after_cells(settings, records)
        return Verdict(
            verdict.status, verdict.fraction, verdict.feedback, {RAN_CELLS: True, **verdict.measurements}
        )


def _judge_after_cells(settings: CompareConfig, records: Sequence[CallRecord]) -> Verdict:
    """The verdict once the cells call was made (records: the cells call, then compare() when made)."""
    cells = records[0].outcome
    if cells.status is not OutcomeStatus.OK:
        return _cells_failed(settings, cells.status, cells.message)
    bound = bound_tables_of(cells.value, cells.call.kwargs.get("bind"))
    ran: list[int]
    tables: list[NotebookTable]
    if bound is not None:
        ran, tables = [], bound
        preface = bound_preface(bound)
    else:
        ran, tables = cells_value(cells.value)
        # No wall time here (the problem's timings carry it): same bytes and seed, same verdict.
        preface = fallback_preface(cells.value) + (
            f"Ran your notebook's {len(ran)} code cell{'' if len(ran) == 1 else 's'} in the sandbox (within the limit of {settings.cells_seconds:g} s), then called compare()"  # noqa: E501
            if not (ran and ran[0] == SCRIPT_CELL)
            else f"Ran your file as a script in the sandbox (within the limit of {settings.cells_seconds:g} s), then called compare()"  # noqa: E501
        )
    measurements: dict[str, PlainValue] = {
        "cells_run": len(ran),
        "notebook_tables": 0 if bound else len(tables),
        "tables_bound": len(bound or ()),
    }
    if len(records) < 2:
        return Verdict("error", 0.0, f"{preface}; compare() was not called.", measurements)
    compare = records[1].outcome
    early = outcome_verdict(records[1:])
    if early is not None and compare.status is OutcomeStatus.EPISODE_LIMIT:
        hint = f" compare() plays the tables your notebook's cells already trained; training inside compare() plays thousands of games ({_left(tables)} {_listed(tables)})."  # noqa: E501
        return Verdict(
            "failed", 0.0, f"{preface}: {early.feedback}.{hint}", {**early.measurements, **measurements}
        )
    if early is not None and compare.status is OutcomeStatus.EXCEPTION and not tables:
        script = bool(ran) and ran[0] == SCRIPT_CELL
        return Verdict(
            "failed",
            0.0,
            f"{preface}. {_NO_TABLES_SCRIPT if script else _NO_TABLES_NOTEBOOK}. {early.feedback}",
            {**early.measurements, **measurements},
        )
    if early is not None:
        return Verdict(
            early.status, 0.0, f"{preface}: {early.feedback}", {**early.measurements, **measurements}
        )
    return _judge_compare(settings, records[1], tables, preface, measurements)


_TRAINING = '`q_table_decay, _ = qlearn("Taxi-v3", decay=True)` and `sarsa_table_decay = sarsa0("Taxi-v3", decay=True)`'  # noqa: E501
_NO_TABLES_SCRIPT = (
    "Run as a script, your file left no Taxi Q-table for compare() to play: compare() plays the tables the notebook's training cells make (the lab's Problem 7), and your .py's cells (or, unmarked, its whole file) trained none. "  # noqa: E501
    f'Train them where a script runs them, under `if __name__ == "__main__":` (as the notebook\'s cells do: {_TRAINING}), or submit the notebook'  # noqa: E501
)
_NO_TABLES_NOTEBOOK = (
    "Your notebook's cells left no Taxi Q-table for compare() to play: compare() plays the tables the notebook's training cells make (the lab's Problem 7). "  # noqa: E501
    f"Train them in cells before compare() is called ({_TRAINING}), then Restart & Run All"
)


def _judge_compare(
    settings: CompareConfig,
    record: CallRecord,
    tables: list[NotebookTable],
    preface: str,
    measurements: dict[str, PlainValue],
) -> Verdict:
    value = record.outcome.value
    means = (
        [as_number(item) for item in value] if isinstance(value, list | tuple) and len(value) == 2 else [None]
    )
    if None in means:
        return _fail(
            f"{preface}, which returned {describe(value)}; expected two numbers (mean total reward with the Q-learning table, with the SARSA table).",  # noqa: E501
            measurements,
        )
    returned = (float(means[0]), float(means[1]))  # type: ignore[arg-type]
    measurements.update({"returned_q_mean": returned[0], "returned_sarsa_mean": returned[1]})
    episodes = played_episodes([record])
    problem = integrity_problem([record], episodes, settings.game_rules())
    if problem:
        return _fail(f"{preface}: {problem}.", measurements)
    per_table = settings.episodes_per_table
    measurements["episodes_replayed"] = len(episodes)
    if len(episodes) < 2 * per_table:
        few = (
            "no episode"
            if not episodes
            else "a single episode per table"
            if len(episodes) <= 2
            else f"{len(episodes)} episodes in all"
        )
        return _fail(
            f"{preface}: it played {few}; the lab asks for {per_table} greedy episodes with each table and the means of their total rewards.",  # noqa: E501
            measurements,
        )
    halves = (episodes[:per_table], episodes[per_table : 2 * per_table])
    if not tables:
        return _fail(
            f"{preface}: your cells left no Taxi Q-table (a 500 x 6 array) in the notebook's globals and none came from qlearn() or sarsa0(), so compare() cannot have played the notebook's tables. "  # noqa: E501
            "Train them in cells (as the template's last cell does) and have compare() read those globals.",
            measurements,
        )
    played: list[NotebookTable] = []
    for which, half in zip(("first", "second"), halves, strict=True):
        table, wrong, steps = _revealed(half, tables)
        if table is None:
            if wrong > steps * RANDOM_SHARE:
                why = f"{wrong} of its {steps} actions were not the argmax of any of {_whose(tables)}, as in random play: act with np.argmax(table[state])"  # noqa: E501
            else:
                why = (
                    f"its actions are greedy on no table {_made(tables)} (compare() must not train or load tables of its own: "  # noqa: E501
                    f"read the globals the cells set; {_left(tables)} {_listed(tables)})"
                )
            return _fail(f"{preface}: in the {which} {per_table} episodes {why}.", measurements)
        played.append(table)
    replayed = tuple(float(np.mean([episode.total_reward for episode in half])) for half in halves)
    measurements.update({"replayed_first_mean": replayed[0], "replayed_second_mean": replayed[1]})
    order = _order(played)
    if order is None:
        return _fail(
            f"{preface}: both halves of its episodes were played with the same table, {played[0].label}; compare() plays the Q-learning table, then the SARSA table.",  # noqa: E501
            measurements,
        )
    wrong_table = _not_decayed(played, tables)
    if wrong_table is not None:
        return _fail(f"{preface}: {wrong_table}", measurements)
    q_index, sarsa_index = order
    expected = (replayed[q_index], replayed[sarsa_index])
    exact = [greedy_policy_return(played[index].table) for index in (q_index, sarsa_index)]
    tests = [
        mean_tolerance(moments.mean, moments.variance, per_table, settings.mean_alpha) for moments in exact
    ]
    measurements.update({"exact_q_mean": exact[0].mean, "exact_sarsa_mean": exact[1].mean})
    names = (played[q_index].label, played[sarsa_index].label)
    story = (
        f"it played {per_table} greedy episodes with {names[0]} (replayed mean {expected[0]:.3f}; its exact greedy return is {exact[0].mean:.3f} ± {tests[0].half_width:.3f}) "  # noqa: E501
        f"and {per_table} with {names[1]} (replayed mean {expected[1]:.3f}; exact {exact[1].mean:.3f} ± {tests[1].half_width:.3f})"  # noqa: E501
    )
    if not _close(returned, expected):
        if _close(returned, expected[::-1]):
            return _fail(
                f"{preface}: {story}, but returned ({returned[0]:.3f}, {returned[1]:.3f}): the means are swapped. Return (Q-learning mean, SARSA mean) in that order.",  # noqa: E501
                measurements,
            )
        return _fail(
            f"{preface}: {story}, but returned ({returned[0]:.6g}, {returned[1]:.6g}), which are not those means: return the mean TOTAL reward of each table's episodes.",  # noqa: E501
            measurements,
        )
    if not all(test.accepts(mean) for test, mean in zip(tests, expected, strict=True)):
        return _fail(
            f"{preface}: {story}; a mean beyond its tolerance (false-fail probability {settings.mean_alpha:g} each) means the episodes were not played from env.reset() without a seed until they ended.",  # noqa: E501
            measurements,
        )
    return Verdict("passed", 1.0, f"{preface}: {story}, and returned those two means.", measurements)


def _revealed(
    half: Sequence[Episode], tables: Sequence[NotebookTable]
) -> tuple[NotebookTable | None, int, int]:
    """The first table on which every action of the half is greedy (None: none), else the fewest misses."""
    fewest, steps = None, 0
    for table in tables:
        best = table.table.max(axis=1)
        wrong = steps = 0
        for episode in half:
            for state, action in episode.decisions():
                steps += 1
                row = table.table[int(state)]
                if not (
                    isinstance(action, int | np.integer)
                    and 0 <= int(action) < 6
                    and row[int(action)] == best[int(state)]
                ):
                    wrong += 1
        if wrong == 0:
            return table, 0, steps
        fewest = wrong if fewest is None else min(fewest, wrong)
    return None, fewest or 0, steps


def _order(played: Sequence[NotebookTable]) -> tuple[int, int] | None:
    """(index of the Q-learning half, index of the SARSA half); None when both are one table."""
    first, second = played
    if first is second or np.array_equal(np.argmax(first.table, axis=1), np.argmax(second.table, axis=1)):
        return None
    if first.learner == "sarsa0" and second.learner == "qlearn":
        return 1, 0
    return 0, 1


def _not_decayed(played: Sequence[NotebookTable], tables: Sequence[NotebookTable]) -> str | None:
    """Why a half played a constant-epsilon table when the notebook has its learner's decaying one."""
    for table in played:
        if table.decay is not False:
            continue
        decayed = [
            other
            for other in tables
            if other.learner == table.learner and other.decay is True and other is not table
        ]
        if decayed:
            return (
                f"it played {table.label}, trained with a constant epsilon, but compare() uses the tables trained with "  # noqa: E501
                f"a decaying epsilon: your notebook has {decayed[0].label}."
            )
    return None


def _whose(tables: Sequence[NotebookTable]) -> str:
    return "the tables bound to your globals" if tables and tables[0].bound else "your notebook's tables"


def _made(tables: Sequence[NotebookTable]) -> str:
    return "bound to your globals" if tables and tables[0].bound else "your notebook's cells made"


def _left(tables: Sequence[NotebookTable]) -> str:
    return "the grader bound" if tables and tables[0].bound else "the cells left"


def _listed(tables: Sequence[NotebookTable]) -> str:
    return ", ".join(table.label for table in tables) or "no Taxi Q-table"


def _close(returned: tuple[float, float], expected: tuple[float, float]) -> bool:
    return all(
        abs(a - b) <= RETURN_TOLERANCE * max(1.0, abs(b)) for a, b in zip(returned, expected, strict=True)
    )


def _cells_failed(settings: CompareConfig, status: OutcomeStatus, message: str) -> Verdict:
    """A cell that raised, ran out of time or crashed the child: that is compare()'s result."""
    measurements: dict[str, PlainValue] = {"cells_outcome": str(status.value)}
    if status is OutcomeStatus.TIMEOUT and message.startswith(IMPORT_TIMEOUT):
        # The file itself did not import in time (training at its top level): no cell ran.
        return Verdict("timeout", 0.0, message, measurements)
    if status is OutcomeStatus.TIMEOUT:
        return Verdict(
            "timeout",
            0.0,
            f"Ran your notebook's code cells in the sandbox, in order: together they did not finish within {settings.cells_seconds:g} seconds (this assignment's limit for running them), so compare() was not called. "  # noqa: E501
            "Keep the training cells to what compare() needs (the lab's N), and move long demos out of the notebook.",  # noqa: E501
            measurements,
        )
    first_line = message.split("\n", 1)[0]  # the rest is the runner's own traceback, not the student's
    not_attempted = first_line.partition("NotAttemptedError: ")[2]
    if not_attempted:
        return Verdict(
            "missing",
            0.0,
            f"{not_attempted}: not attempted yet. Write compare() (it plays the tables your training cells make).",  # noqa: E501
            measurements,
        )
    what = first_line.partition("NotebookCellError: ")[2] or first_line
    if "raised NotImplementedError" in what:
        return Verdict(
            "missing",
            0.0,
            f"Ran your notebook's code cells in the sandbox, in order: {what}, so compare() was not called: not attempted yet. "  # noqa: E501
            "Write the functions the training cells call (sarsa0) and compare().",
            measurements,
        )
    return Verdict(
        "error",
        0.0,
        f"Ran your notebook's code cells in the sandbox, in order, as Restart & Run All does: {what}, so the run stopped there and compare() was not called. "  # noqa: E501
        "Fix that cell, run the whole notebook again (Kernel > Restart & Run All), save it and submit again.",
        measurements,
    )


def _fail(feedback: str, measurements: dict[str, PlainValue]) -> Verdict:
    return Verdict("failed", 0.0, feedback, measurements)
