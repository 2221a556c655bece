"""The MDPs the second lab's functions are graded on, each with the discounts it is graded at.

The lab's worked example alone would let a file that hard-codes its answers, or that reads only the first
outcome of each move, or that forgets the discount, pass. So the grader also owns: FrozenLake 4x4 and 8x8,
deterministic and slippery, built here from their maps exactly as gymnasium 1.4 builds them (the side slips
are `(1 - 1/3) / 2 = 0.33333333333333337`, the intended move `1/3`, outcomes listed left of the intended
move, the move, right of it, duplicates kept); a windy corridor (stochastic, rewards on every step,
graded below discount 1) and a ring (stochastic, negative rewards, where the all-zeros start policy of
policy iteration loops forever at discount 1 while the lab's all-ones start ends).

Those ten cases are public (they are in this file), so a file could memorise their answers. A grading seed
therefore adds held-out cases (`held_out_cases(seed)`): random MDPs of varied size drawn from the seed
(`random_mdp`), each with terminal states, stochastic moves of one to three outcomes and rewards on every
move, graded below discount 1 so that every policy has a finite value, value iteration contracts and no
policy's evaluation can loop forever. `grading_cases(seed)` is the public cases followed by those.
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


def windy_corridor() -> Mdp:
    """Seven cells in a row and an exit (state 7): a gust may push the walker back.

    Action 0 walks left: from cell 0 it leaves through the small door (reward 1, episode over); elsewhere it
    moves one cell left (reward -0.1). Action 1 walks right against the wind: it moves right with probability
    0.7 (reward -0.1, or 10 when it leaves through the big door after cell 6), stays with probability 0.2
    (reward -0.2) and is blown one cell left with probability 0.1 (reward -0.3). Every move pays a reward, so
    a discount counted from the wrong step changes every value; every rightward move has three outcomes with
    three rewards, so reading one outcome, or overwriting instead of adding, changes them too.
    """
    cells, exit_state = 7, 7
    table: list[Actions] = []
    for cell in range(cells):
        left = ((1.0, exit_state, 1.0, True),) if cell == 0 else ((1.0, cell - 1, -0.1, False),)
        ahead = (0.7, exit_state, 10.0, True) if cell == cells - 1 else (0.7, cell + 1, -0.1, False)
        right = (ahead, (0.2, cell, -0.2, False), (0.1, max(cell - 1, 0), -0.3, False))
        table.append((left, right))
    table.append((((1.0, exit_state, 0.0, True),), ((1.0, exit_state, 0.0, True),)))
    return Mdp("a windy corridor", tuple(table))


def ring() -> Mdp:
    """Four states on a ring and an exit (state 4), with four actions.

    Action 0 walks on to the next state of the ring at a cost (reward -1): a policy of walking never ends.
    Action 1 leaves at once with a reward equal to the state's number. Action 2 gambles: with probability 0.5
    it leaves with reward 3, otherwise it moves two states on (reward 0). Action 3 waits where it is (reward
    -0.5). At discount 1 every policy that never ends has no finite value, so the optimum is unique.
    """
    states, exit_state = 4, 4
    table: list[Actions] = []
    for state in range(states):
        walk = ((1.0, (state + 1) % states, -1.0, False),)
        leave = ((1.0, exit_state, float(state), True),)
        gamble = ((0.5, exit_state, 3.0, True), (0.5, (state + 2) % states, 0.0, False))
        wait = ((1.0, state, -0.5, False),)
        table.append((walk, leave, gamble, wait))
    table.append(tuple(((1.0, exit_state, 0.0, True),) for _ in range(4)))
    return Mdp("a ring with an exit", tuple(table))


def random_mdp(draw: np.random.Generator, name: str) -> Mdp:
    """A random MDP: 6 to 14 states, 2 to 4 actions, the last 1 or 2 states terminal (a zero-reward self-loop
    per action, as FrozenLake's holes and goal), every other move with 1 to 3 outcomes to distinct states (2
    or 3 for action 0, so every state has a stochastic move).

    Probabilities are Dirichlet(1) draws and rewards uniform on [-1, 1] (a terminal outcome's on [-1, 2]),
    continuous, so two actions tie only with probability 0: a correct greedy step has one answer. `done` is
    True exactly on moves into a terminal state. Every row's probabilities sum to 1 up to rounding.
    """
    n_states = int(draw.integers(6, 15))
    n_actions = int(draw.integers(2, 5))
    n_terminal = int(draw.integers(1, 3))
    terminal = set(range(n_states - n_terminal, n_states))
    table: list[Actions] = []
    for state in range(n_states):
        if state in terminal:
            table.append(tuple(((1.0, state, 0.0, True),) for _ in range(n_actions)))
            continue
        actions: list[tuple[Outcome, ...]] = []
        for action in range(n_actions):
            count = int(draw.integers(2 if action == 0 else 1, 4))  # some move of every state is stochastic
            targets = draw.choice(n_states, size=count, replace=False)
            weights = draw.dirichlet(np.ones(count)) if count > 1 else np.ones(1)
            outcomes = []
            for target, weight in zip(targets.tolist(), weights.tolist(), strict=True):
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

    Without a seed, the ten public cases; with a problem's seed, those and `held_out_cases(seed)`.
    """
    if seed is not None:
        return (*grading_cases(), *held_out_cases(seed))
    example, corridor, circle = lab_example(), windy_corridor(), ring()
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
        GradingCase("corridor_0.95", corridor, 0.95, "rewards on every step and three outcomes per move"),
        GradingCase(
            "ring", circle, 1.0, "negative rewards; all-zeros starts of policy iteration loop forever"
        ),
        GradingCase("ring_0.8", circle, 0.8, "the same ring discounted: the best action changes"),
    )
