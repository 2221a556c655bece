"""The MDPs the second lab's functions are graded on, each with the discounts it is graded at.

Every one is of the lab's kind: `P[s][a]` for FrozenLake's four actions (Left, Down, Right, Up), terminal
states written as the lab writes them (the example's, FrozenLake's `[(1.0, s, 0, True)]`), and at discount 1
only MDPs on which the lab's own iterative evaluation converges from every start policy the texts allow:
the lab's example (its reward cycle 0 -> 1 -> 0 is the lab's own; the all-zeros and all-ones starts
converge there), FrozenLake (its only reward is the goal, so a policy that never ends has the value 0), and
MDPs of the grader's make on which every policy ends its episodes (`reference.oracles.mdp.trapping_states`
is empty). An MDP on which some policy loops forever through rewards is never asked at discount 1: a start
policy the text allows would never converge on an input the lab never gives.

The lab's worked example alone would let a file that hard-codes its answers, or that reads only the first
outcome of each move, or that forgets the discount, pass. So the grader also owns: FrozenLake 4x4 and 8x8,
deterministic and slippery, built here from their maps exactly as gymnasium 1.4 builds them (the side slips
are `(1 - 1/3) / 2 = 0.33333333333333337`, the intended move `1/3`, outcomes listed left of the intended
move, the move, right of it, duplicates kept); and a windy 2x3 grid (`windy_grid`: four outcomes per move,
rewards on every step, a wind that ends every policy's walk), graded at discount 1 and 0.8.

Those nine cases are public (they are in this file), so a file could memorise their answers. A grading seed
therefore adds held-out cases (`held_out_cases(seed)`): random MDPs of the lab's shape and of varied size
drawn from the seed (`random_mdp`), each with terminal states, stochastic moves of one to three outcomes,
rewards on every move and a first outcome that leads closer to the end (so every policy ends), graded below
discount 1. `grading_cases(seed)` is the public cases followed by those.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

from reference.oracles.mdp import Mdp, Outcome

Actions = tuple[tuple[Outcome, ...], ...]

LEFT, DOWN, RIGHT, UP = 0, 1, 2, 3
"""FrozenLake's actions, as the lab numbers them."""
SLIP_INTENDED = 1.0 / 3.0
SLIP_SIDE = (1.0 - SLIP_INTENDED) / 2.0
"""gymnasium 1.4's slip probabilities: 0.3333333333333333 for the intended move, 0.33333333333333337 aside."""

FROZEN_LAKE_MAPS: dict[str, tuple[str, ...]] = {
    "4x4": ("SFFF", "FHFH", "FFFH", "HFFG"),
    "8x8": (
        "SFFFFFFF",
        "FFFFFFFF",
        "FFFHFFFF",
        "FFFFFHFF",
        "FFFHFFFF",
        "FHHFFFHF",
        "FHFFHFHF",
        "FFFHFFFG",
    ),
}
"""The maps of `FrozenLake-v1` (and `FrozenLake8x8-v1`, the old `-v0` ids): S start, F ice, H hole, G goal."""
TIME_LIMITS = {"FrozenLake-v1": 100, "FrozenLake8x8-v1": 200, "FrozenLake-v0": 100, "FrozenLake8x8-v0": 200}
"""The steps after which `gym.make(id)`'s TimeLimit cuts an episode (the lab's values are without it). The
limit follows the id, not the map: `gym.make('FrozenLake-v1', map_name='8x8')`, as the gymnasium texts
write it, keeps 100 steps, which lowers an optimal 8x8 policy's mean from 1 to about 0.5."""


def lab_example() -> Mdp:
    """The lab's worked example: a 2x2 grid, start 0, terminal 3; moving onto 3 pays 1, some moves cost 1.

    Impossible moves are listed with probability 0, as the lab writes them.
    """
    impossible: tuple[Outcome, ...] = ((0.0, 0, 0.0, False),)
    table = (
        (impossible, ((1.0, 2, -1.0, False),), ((1.0, 1, 0.0, False),), impossible),
        (((1.0, 0, -1.0, False),), ((1.0, 3, 1.0, True),), impossible, impossible),
        (((0.0, 2, -1.0, False),), ((0.0, 2, -1.0, False),), ((1.0, 3, 1.0, True),), ((1.0, 0, 0.0, False),)),
        (((0.0, 0, 0.0, True),), ((0.0, 0, 0.0, True),), ((0.0, 0, 0.0, True),), ((0.0, 0, 1.0, True),)),
    )
    return Mdp("the lab's 4-state example", table)


def frozen_lake(map_name: str, *, slippery: bool) -> Mdp:
    """FrozenLake's table for the 4x4 or 8x8 map, exactly as gymnasium 1.4's `env.unwrapped.P`."""
    rows = FROZEN_LAKE_MAPS[map_name]
    size = len(rows)

    def moved(row: int, column: int, action: int) -> tuple[int, float, bool]:
        if action == LEFT:
            column = max(column - 1, 0)
        elif action == DOWN:
            row = min(row + 1, size - 1)
        elif action == RIGHT:
            column = min(column + 1, size - 1)
        else:
            row = max(row - 1, 0)
        tile = rows[row][column]
        return row * size + column, float(tile == "G"), tile in "GH"

    table: list[Actions] = []
    for row in range(size):
        for column in range(size):
            state = row * size + column
            if rows[row][column] in "GH":
                table.append(tuple(((1.0, state, 0.0, True),) for _ in range(4)))
                continue
            actions: list[tuple[Outcome, ...]] = []
            for action in range(4):
                if slippery:
                    slips = (
                        ((action - 1) % 4, SLIP_SIDE),
                        (action, SLIP_INTENDED),
                        ((action + 1) % 4, SLIP_SIDE),
                    )
                    actions.append(tuple((p, *moved(row, column, direction)) for direction, p in slips))
                else:
                    actions.append(((1.0, *moved(row, column, action)),))
            table.append(tuple(actions))
    kind = "slippery" if slippery else "deterministic"
    return Mdp(f"FrozenLake {map_name} ({kind})", tuple(table))


GRID_COLUMNS = 3
"""The windy grid's width: two rows of three cells, states numbered row by row as FrozenLake's."""
GRID_HOLE, GRID_GOAL = 4, 5
"""The windy grid's terminal states."""
GRID_MOVE, GRID_SLIP, GRID_WIND = 0.7, 0.1, 0.1
"""The windy grid's chances: the move asked for, a slip to either side of it, the wind's push."""


def windy_grid() -> Mdp:
    """Six states on a 2x3 grid with four actions, a hole, a goal and a wind that ends every walk.

        0 1 2
        3 H G      H (state 4): a hole, entering it pays -1; G (state 5): the goal, entering it pays 2.

    A move from a live state (0 to 3) has four outcomes, listed as FrozenLake lists its slips and then the
    wind: a slip to the left of the move asked for (0.1), the move (0.7), a slip to its right (0.1), and the
    wind (0.1), which carries the walker one cell east, or from the east column down into the goal. A move
    into the edge stays put. Every step that does not end the episode pays -0.1. The terminal states hold
    `[(1.0, s, 0, True)]` for every action, as FrozenLake's holes and goal do.

    The wind leads from every live state closer to an end (0 -> 1 -> 2 -> G, 3 -> H) whatever the action,
    so every policy ends its episodes with probability 1 (`trapping_states` is empty) and has a finite value
    at discount 1: the lab's iterative evaluation converges from any start policy. Rewards on every step, four
    outcomes with different rewards and probabilities (the first is not the last) and a discount that trades
    the hole's risk against the walk's cost make a discount from the wrong step, the first or last outcome
    alone, and a discount ignored all change the values.
    """
    rows = 2
    terminal = {GRID_HOLE, GRID_GOAL}

    def moved(state: int, action: int) -> int:
        row, column = divmod(state, GRID_COLUMNS)
        if action == LEFT:
            column = max(column - 1, 0)
        elif action == DOWN:
            row = min(row + 1, rows - 1)
        elif action == RIGHT:
            column = min(column + 1, GRID_COLUMNS - 1)
        else:
            row = max(row - 1, 0)
        return row * GRID_COLUMNS + column

    def blown(state: int) -> int:
        row, column = divmod(state, GRID_COLUMNS)
        return state + 1 if column < GRID_COLUMNS - 1 else (row + 1) * GRID_COLUMNS + column

    def outcome(probability: float, target: int) -> Outcome:
        reward = {GRID_HOLE: -1.0, GRID_GOAL: 2.0}.get(target, -0.1)
        return (probability, target, reward, target in terminal)

    table: list[Actions] = []
    for state in range(rows * GRID_COLUMNS):
        if state in terminal:
            table.append(tuple(((1.0, state, 0.0, True),) for _ in range(4)))
            continue
        table.append(
            tuple(
                (
                    outcome(GRID_SLIP, moved(state, (action - 1) % 4)),
                    outcome(GRID_MOVE, moved(state, action)),
                    outcome(GRID_SLIP, moved(state, (action + 1) % 4)),
                    outcome(GRID_WIND, blown(state)),
                )
                for action in range(4)
            )
        )
    return Mdp("a windy 2x3 grid", tuple(table))


RANDOM_ACTIONS = 4
"""A random MDP's actions: FrozenLake's four, as every MDP of the lab has."""


def random_mdp(draw: np.random.Generator, name: str) -> Mdp:
    """A random MDP of the lab's shape: 6 to 14 states, FrozenLake's four actions, the last 1 or 2 states
    terminal (`[(1.0, s, 0, True)]` for every action, as FrozenLake's holes and goal), every other move with 1
    to 3 outcomes to distinct states (2 or 3 for action 0, so every state has a stochastic move).

    The first outcome of every move leads to a state of a higher number (a terminal one from the last live
    state), so from every state every action may bring the walker closer to a terminal state: every policy
    ends its episodes with probability 1 (`trapping_states` is empty) and has a finite value at any discount.
    Probabilities are Dirichlet(1) draws and rewards uniform on [-1, 1] (a terminal outcome's on [-1, 2]),
    continuous, so two actions tie only with probability 0: a correct greedy step has one answer. `done` is
    True exactly on moves into a terminal state. Every row's probabilities sum to 1 up to rounding.
    """
    n_states = int(draw.integers(6, 15))
    n_terminal = int(draw.integers(1, 3))
    terminal = set(range(n_states - n_terminal, n_states))
    table: list[Actions] = []
    for state in range(n_states):
        if state in terminal:
            table.append(tuple(((1.0, state, 0.0, True),) for _ in range(RANDOM_ACTIONS)))
            continue
        actions: list[tuple[Outcome, ...]] = []
        for action in range(RANDOM_ACTIONS):
            count = int(draw.integers(2 if action == 0 else 1, 4))  # some move of every state is stochastic
            ahead = int(draw.integers(state + 1, n_states))  # a step closer to the end, whatever the policy
            others = [s for s in range(n_states) if s != ahead]
            targets = [ahead, *draw.choice(others, size=count - 1, replace=False).tolist()]
            weights = draw.dirichlet(np.ones(count)) if count > 1 else np.ones(1)
            outcomes = []
            for target, weight in zip(targets, weights.tolist(), strict=True):
                ends = target in terminal
                reward = float(draw.uniform(-1.0, 2.0 if ends else 1.0))
                outcomes.append((float(weight), int(target), reward, ends))
            actions.append(tuple(outcomes))
        table.append(tuple(actions))
    return Mdp(name, tuple(table))


HELD_OUT = 3
"""Random MDPs a grading seed adds to the public cases."""
HELD_OUT_DISCOUNTS = (0.8, 0.9, 0.95)
"""The discounts a held-out MDP is graded at (one drawn per MDP): below 1, so every policy's value is finite
and value iteration at tol 1e-8 needs at most about 470 sweeps (rewards within 2, 0.95**470 * 40 < 1e-8)."""


def seeded_draw(seed: int, purpose: str) -> np.random.Generator:
    """A generator for one purpose under one seed: a stable hash of both, so each purpose draws apart."""
    digest = hashlib.sha256(f"gymgrade-rl2:{seed}:{purpose}".encode()).digest()
    return np.random.default_rng(int.from_bytes(digest[:8], "big"))


@dataclass(frozen=True)
class GradingCase:
    """One MDP at one discount, as the grader passes it to a student's function.

    Attributes:
        key: a short identifier, stable across releases (reports and seeds use it).
        mdp: the MDP.
        beta: the discount factor passed.
        why: what the case can reveal that the others cannot.
    """

    key: str
    mdp: Mdp
    beta: float
    why: str


def held_out_cases(seed: int) -> tuple[GradingCase, ...]:
    """The `HELD_OUT` random MDPs and discounts a grading seed adds (the same for the same seed)."""
    cases = []
    for index in range(HELD_OUT):
        draw = seeded_draw(seed, f"mdp {index}")
        mdp = random_mdp(draw, f"a random MDP ({index + 1} of {HELD_OUT} drawn from the grading seed)")
        beta = HELD_OUT_DISCOUNTS[int(draw.integers(len(HELD_OUT_DISCOUNTS)))]
        why = "held out: drawn from the grading seed, so no file can know it in advance"
        cases.append(GradingCase(f"random{index + 1}_{beta:g}", mdp, beta, why))
    return tuple(cases)


def grading_cases(seed: int | None = None) -> tuple[GradingCase, ...]:
    """Every MDP and discount the second lab's pure functions are graded on, the lab's example first.

    Without a seed, the nine public cases; with a problem's seed, those and `held_out_cases(seed)`.
    """
    if seed is not None:
        return (*grading_cases(), *held_out_cases(seed))
    example, grid = lab_example(), windy_grid()
    lake4, lake8 = frozen_lake("4x4", slippery=True), frozen_lake("8x8", slippery=True)
    still4, still8 = frozen_lake("4x4", slippery=False), frozen_lake("8x8", slippery=False)
    return (
        GradingCase("example", example, 1.0, "the lab's own example and answers [1, 1, 1, 0], n = 3"),
        GradingCase("example_0.9", example, 0.9, "the example discounted: [0.9, 1, 1, 0]"),
        GradingCase(
            "lake4", lake4, 1.0, "stochastic moves with repeated outcomes; terminal states self-loop"
        ),
        GradingCase("lake4_0.9", lake4, 0.9, "stochastic and discounted"),
        GradingCase("lake8", lake8, 1.0, "many tied optimal actions; the start's value is 1"),
        GradingCase(
            "still4_0.8", still4, 0.8, "deterministic and discounted: the value is beta**(steps - 1)"
        ),
        GradingCase(
            "still8_0.9",
            still8,
            0.9,
            "deterministic, larger; below discount 1, since at 1 almost every move ties and the lab's own "
            "first-argmax policy walks into a wall forever",
        ),
        GradingCase(
            "grid",
            grid,
            1.0,
            "rewards on every step, four outcomes per move; every policy ends, so any start converges",
        ),
        GradingCase("grid_0.8", grid, 0.8, "the same grid discounted: the walk's cost weighs less"),
    )
