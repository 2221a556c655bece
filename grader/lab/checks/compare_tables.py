"""The Taxi Q-tables the grader binds for `compare()` in place of the notebook's training (edition rl1).

compare()'s verdict does not depend on what training learned: the judge identifies each table from the
greedy episodes compare() played and compares each mean with that table's exact greedy return. So the
grader chooses the tables, one per learner and epsilon schedule (`bound_tables`), drawn from the problem's
seed (the same seed gives the same bytes): each is the optimal table of Taxi with a few extra walls
(`reference.oracles.taxi.walled_q_table`), every row's ties broken by a seeded order, so that

- greedy play on it takes the walled map's optimal routes in the real Taxi and ends from every start within
  the 200-step limit (checked on the exact model, every start);
- every row has one maximiser, so any greedy rule (first maximiser, random among ties) plays one policy;
- any two tables choose different actions on the greedy route of at least `MIN_REVEALING_STARTS` of the
  starts, so a half of 1 000 episodes played with one is greedy on no other (the chance it is not revealed
  is below 0.5 ** 1000), and a compare() that plays a table of its own (the optimal one, say) is told apart;
- its exact greedy return is known (`reference.oracles.greedy_policy_return`).

A draw that misses a condition is drawn again from the same generator, so the result stays a function of
the seed.
"""

from __future__ import annotations

from functools import cache
from itertools import combinations

import numpy as np
import numpy.typing as npt

from reference.oracles.taxi import ACTIONS, STATES, TIME_LIMIT, taxi_model, walled_q_table

FloatArray = npt.NDArray[np.float64]

LEARNERS = ("qlearn", "sarsa0")
"""The notebook's learners, as the child's binding names them."""
SCHEDULES = ("decay", "constant")
"""A learner's tables: trained with a decaying epsilon (what compare() plays) or a constant one."""
WALLS = {"decay": 2, "constant": 4}
"""Extra wall segments per table: the constant-epsilon tables take longer detours (lower returns)."""
MIN_REVEALING_STARTS = 0.5
"""Least share of the starts whose greedy route on one table meets a state where another table differs."""
TIE_BREAK = 1e-9
"""Scale of the seeded tie-break: far below the gap between distinct action values (they differ by at
least gamma ** 30 ~ 2e-7 times a step's reward on the longest routes), far above value iteration's 1e-12."""
MAX_DRAWS = 1000


def _segments() -> list[tuple[tuple[int, int, int], tuple[int, int, int]]]:
    """Every wall segment between two neighbouring cells, as its two blocked moves (row, column, action)."""
    segments = []
    for row in range(5):
        for column in range(5):
            if column < 4:  # east from (row, column), west from (row, column + 1)
                segments.append(((row, column, 2), (row, column + 1, 3)))
            if row < 4:  # south from (row, column), north from (row + 1, column)
                segments.append(((row, column, 0), (row + 1, column, 1)))
    return segments


def _greedy_routes(actions: npt.NDArray[np.int64]) -> tuple[bool, list[list[int]]]:
    """Whether greedy play ends from every start within the time limit, and each start's route."""
    model = taxi_model()
    routes: list[list[int]] = []
    for start in np.flatnonzero(model.initial_distribution > 0):
        state, route = int(start), []
        for _ in range(TIME_LIMIT):
            route.append(state)
            action = int(actions[state])
            if model.terminates[state, action]:
                break
            state = int(model.next_state[state, action])
        else:
            return False, routes
        routes.append(route)
    return True, routes


def _drawn_table(rng: np.random.Generator, walls: int, gamma: float) -> FloatArray | None:
    segments = _segments()
    chosen = rng.choice(len(segments), size=walls, replace=False)
    blocked = tuple(move for index in sorted(chosen) for move in segments[index])
    raw = walled_q_table(blocked, gamma)
    order = np.argsort(rng.random((STATES, ACTIONS)), axis=1).astype(np.float64)
    table = raw - TIE_BREAK * order
    actions = np.argmax(table, axis=1)
    ranked = np.sort(table, axis=1)
    unique = bool(np.all(ranked[:, -1] > ranked[:, -2]))
    optimal_in_walled_map = bool(np.all(raw[np.arange(STATES), actions] >= raw.max(axis=1) - 1e-10))
    ends, _ = _greedy_routes(actions)
    return table if unique and optimal_in_walled_map and ends else None


def _revealing_share(first: FloatArray, second: FloatArray) -> float:
    """The share of starts whose greedy route on `first` meets a state where `second` acts otherwise."""
    differs = np.argmax(first, axis=1) != np.argmax(second, axis=1)
    _, routes = _greedy_routes(np.argmax(first, axis=1))
    return float(np.mean([bool(np.any(differs[route])) for route in routes]))


@cache
def bound_tables(seed: int, gamma: float = 0.6) -> dict[str, dict[str, FloatArray]]:
    """The grader's tables for a problem seed: ``{learner: {schedule: (500, 6) table}}``.

    Raises:
        RuntimeError: no draw met the conditions within `MAX_DRAWS` (never seen: most draws do).
    """
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(0xC0DE,)))
    keys = [(learner, schedule) for learner in LEARNERS for schedule in SCHEDULES]
    for _ in range(MAX_DRAWS):
        tables = [_drawn_table(rng, WALLS[schedule], gamma) for _, schedule in keys]
        if any(table is None for table in tables):
            continue
        drawn: list[FloatArray] = [table for table in tables if table is not None]
        if all(
            _revealing_share(a, b) >= MIN_REVEALING_STARTS and _revealing_share(b, a) >= MIN_REVEALING_STARTS
            for a, b in combinations(drawn, 2)
        ):
            result: dict[str, dict[str, FloatArray]] = {learner: {} for learner in LEARNERS}
            for (learner, schedule), table in zip(keys, drawn, strict=True):
                table.flags.writeable = False
                result[learner][schedule] = table
            return result
    raise RuntimeError(f"no set of compare() tables met the conditions in {MAX_DRAWS} draws (seed {seed})")
