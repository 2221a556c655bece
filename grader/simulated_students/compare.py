"""Simulated `compare()` students (edition rl1) and the cells call made before it.

The cells call leaves the notebook's globals in `NAMESPACE`, as the child's module globals, in one of two
ways: `binds` as the default configuration does (the grader's seeded tables bound to the template's names
`q_table_decay`, `sarsa_table_decay` and `q_table`, `grader.sandbox.child.binding`), `cells` as running
every cell does (the tables a notebook's training cells left: the grader's two taxi tables, labelled as the
decaying-epsilon Q-learning and SARSA tables, and a constant-epsilon Q-learning table). Each student reads
them from `NAMESPACE` and plays on them as its `compare()` would.
"""

from __future__ import annotations

from functools import cache
from typing import Any

import numpy as np
import numpy.typing as npt

from grader.lab.checks.taxi_tables import grader_tables
from grader.simulated_students.simulation import Lab
from grader.simulated_students.taxi_tables import EPISODES, _play
from reference.oracles import greedy_policy_return, optimal_q_table
from reference.oracles.taxi import ACTIONS

GAMMA = 0.6
NAMESPACE: dict[str, npt.NDArray[np.float64]] = {}
"""The simulated notebook's globals, as the last cells call left them."""
_TEMPLATE_NAMES = {
    "q_table_decay": ("qlearn", True, 'q_table_decay, _ = qlearn("Taxi-v3", decay=True)'),
    "sarsa_table_decay": ("sarsa0", True, 'sarsa_table_decay = sarsa0("Taxi-v3", decay=True)'),
    "q_table": ("qlearn", False, 'q_table, _ = qlearn("Taxi-v3")'),
}


@cache
def notebook_tables() -> dict[str, npt.NDArray[np.float64]]:
    """The tables the simulated notebook trained: by global name."""
    detour, optimal = grader_tables(GAMMA)
    constant = np.random.default_rng(20261125).random((500, ACTIONS))
    return {"q_table_decay": detour, "sarsa_table_decay": optimal, "q_table": constant}


def cells(_lab: Lab, *_args: Any, **_kwargs: Any) -> dict[str, Any]:
    """What the cells call returns after a notebook trained its three tables."""
    tables = notebook_tables()
    NAMESPACE.clear()
    NAMESPACE.update(tables)
    labels = {
        "q_table_decay": ("qlearn", True),
        "sarsa_table_decay": ("sarsa0", True),
        "q_table": ("qlearn", False),
    }
    return {
        "cells": [{"cell": number, "seconds": 0.5} for number in (2, 4, 6, 8)],
        "tables": [
            {
                "names": [name],
                "learner": labels[name][0],
                "decay": labels[name][1],
                "N": 70_000,
                "table": table,
            }
            for name, table in tables.items()
        ],
    }


def binds(_lab: Lab, *_args: Any, bind: dict[str, dict[str, Any]], **_kwargs: Any) -> dict[str, Any]:
    """What the cells call returns after binding the grader's tables to the template's three names."""
    NAMESPACE.clear()
    bound = []
    for cell, (name, (learner, decay, statement)) in enumerate(_TEMPLATE_NAMES.items(), start=20):
        NAMESPACE[name] = np.array(bind[learner]["decay" if decay else "constant"])
        bound.append(
            {
                "name": name,
                "learner": learner,
                "decay": decay,
                "N": 70_000,
                "cell": cell,
                "line": 1,
                "statement": statement,
                "read": name != "q_table",
            }
        )
    return {"bound": bound, "cells": [], "tables": []}


def _tables() -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    return NAMESPACE["q_table_decay"], NAMESPACE["sarsa_table_decay"]


def honest(lab: Lab) -> tuple[float, float]:
    """The lab's compare(): 1 000 greedy episodes with each decaying-epsilon table, both means."""
    q_table, sarsa_table = _tables()
    return _play(lab, q_table, EPISODES), _play(lab, sarsa_table, EPISODES)


def sarsa_first(lab: Lab) -> tuple[float, float]:
    """Honest too: plays the SARSA table first, but returns the Q-learning mean first."""
    q_table, sarsa_table = _tables()
    sarsa = _play(lab, sarsa_table, EPISODES)
    return _play(lab, q_table, EPISODES), sarsa


def swapped(lab: Lab) -> tuple[float, float]:
    first, second = honest(lab)
    return second, first


def random_play(lab: Lab) -> tuple[float, float]:
    q_table, sarsa_table = _tables()
    return _play(lab, q_table, EPISODES, random_play=True), _play(
        lab, sarsa_table, EPISODES, random_play=True
    )


def single_episode(lab: Lab) -> tuple[float, float]:
    q_table, sarsa_table = _tables()
    return _play(lab, q_table, 1), _play(lab, sarsa_table, 1)


def same_table(lab: Lab) -> tuple[float, float]:
    q_table, _ = _tables()
    return _play(lab, q_table, EPISODES), _play(lab, q_table, EPISODES)


def constant_epsilon_table(lab: Lab) -> tuple[float, float]:
    _, sarsa_table = _tables()
    return _play(lab, NAMESPACE["q_table"], EPISODES), _play(lab, sarsa_table, EPISODES)


def own_tables(lab: Lab) -> tuple[float, float]:
    """Plays tables the notebook never made (here: the optimal table breaking ties the other way)."""
    q_table, _ = _tables()
    own = optimal_q_table(GAMMA) + 1e-6 * np.arange(ACTIONS)
    return _play(lab, q_table, EPISODES), _play(lab, own, EPISODES)


def exact_constants(_lab: Lab) -> tuple[float, float]:
    """Plays nothing: returns the exact greedy returns of the tables it reads (as if it knew the oracle)."""
    q_table, sarsa_table = _tables()
    return greedy_policy_return(q_table).mean, greedy_policy_return(sarsa_table).mean


def final_reward(lab: Lab) -> tuple[float, float]:
    q_table, sarsa_table = _tables()
    return _play(lab, q_table, EPISODES, final_only=True), _play(lab, sarsa_table, EPISODES, final_only=True)


MISTAKES: dict[str, tuple[Any, str]] = {
    "swapped": (swapped, "the means are swapped"),
    "random_play": (random_play, "as in random play"),
    "single_episode": (single_episode, "a single episode per table"),
    "same_table": (same_table, "played with the same table"),
    "constant_epsilon_table": (constant_epsilon_table, "trained with a constant epsilon"),
    "own_tables": (own_tables, "greedy on no table"),
    "final_reward": (final_reward, "which are not those means"),
    "exact_constants": (exact_constants, "it played no episode"),
}
"""Mistakes: (the function, words its feedback must contain). Each must fail."""
