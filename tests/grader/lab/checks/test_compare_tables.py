"""The tables the grader binds for compare(): a function of the seed, tie-free, delivering from every start,
told apart from each other and from the optimal table (`grader.lab.checks.compare_tables`)."""

from itertools import combinations

import numpy as np
import pytest

from grader.lab.checks.compare_tables import (
    LEARNERS,
    MIN_REVEALING_STARTS,
    SCHEDULES,
    _greedy_routes,
    _revealing_share,
    bound_tables,
)
from reference.oracles import greedy_policy_return, optimal_q_table


def _all(seed: int) -> list[np.ndarray]:
    tables = bound_tables(seed)
    return [tables[learner][schedule] for learner in LEARNERS for schedule in SCHEDULES]


@pytest.mark.slow  # draws three sets of tables, a second or two under load
def test_the_same_seed_gives_the_same_bytes_and_another_seed_other_tables() -> None:
    first = [table.tobytes() for table in _all(11)]
    bound_tables.cache_clear()
    assert [table.tobytes() for table in _all(11)] == first
    assert [table.tobytes() for table in _all(12)] != first


@pytest.mark.slow  # walks every start's greedy route on every table
@pytest.mark.parametrize("seed", [0, 1, 2, 3, 2**62 + 5])
def test_every_table_is_tie_free_delivers_from_every_start_and_is_told_apart(seed: int) -> None:
    tables = _all(seed)
    for table in tables:
        assert table.shape == (500, 6) and not table.flags.writeable
        ranked = np.sort(table, axis=1)
        assert np.all(ranked[:, -1] > ranked[:, -2])  # one maximiser a row: one policy
        ends, routes = _greedy_routes(np.argmax(table, axis=1))
        assert ends and len(routes) == 300
        assert greedy_policy_return(table).mean > 0  # every episode delivers within the time limit
    for a, b in combinations(tables, 2):
        assert _revealing_share(a, b) >= MIN_REVEALING_STARTS
        assert _revealing_share(b, a) >= MIN_REVEALING_STARTS
    optimal = optimal_q_table(0.6) - 1e-6 * np.arange(6)
    assert all(np.any(np.argmax(table, axis=1) != np.argmax(optimal, axis=1)) for table in tables)
