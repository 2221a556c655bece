"""Every MDP the second lab is graded on is of the lab's kind: FrozenLake's four actions, terminal states as
the lab writes them, and at discount 1 only MDPs on which the lab's evaluation converges from any start (every
policy of a grader-made MDP ends its episodes, proved here by an absorbing-chain check of every deterministic
policy). The held-out random MDPs a grading seed adds (`reference.oracles.mdps.held_out_cases`) are well
posed for every pure problem, the same for the same seed and different for another."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from grader.lab.rl2.checks.mdp_calls import READINGS, bellman_sweep, iterate
from reference.oracles.mdp import (
    Mdp,
    optimal_solution,
    policy_value,
    q_values,
    terminal_states,
    trapping_states,
)
from reference.oracles.mdps import (
    HELD_OUT,
    frozen_lake,
    grading_cases,
    held_out_cases,
    lab_example,
    random_mdp,
    seeded_draw,
    windy_grid,
)

SEEDS = range(200)
"""Seeds checked: 600 random MDPs (about 10 s)."""


def test_the_same_seed_draws_the_same_mdps_and_another_seed_others() -> None:
    assert held_out_cases(7) == held_out_cases(7)
    first, second = held_out_cases(7), held_out_cases(8)
    assert all(a.mdp.table != b.mdp.table for a, b in zip(first, second, strict=True))
    assert grading_cases(7)[: len(grading_cases())] == grading_cases()
    assert len(grading_cases(7)) == len(grading_cases()) + HELD_OUT


def test_the_draws_of_two_purposes_differ() -> None:
    assert seeded_draw(1, "values a").uniform() != seeded_draw(1, "values b").uniform()
    assert seeded_draw(1, "values a").uniform() == seeded_draw(1, "values a").uniform()


@pytest.mark.slow
def test_every_held_out_mdp_is_well_posed_for_every_problem() -> None:
    sizes = set()
    for seed in SEEDS:
        for case in held_out_cases(seed):
            mdp, beta = case.mdp, case.beta
            sizes.add((mdp.n_states, mdp.n_actions))
            assert beta < 1
            moves = mdp.transitions()
            np.testing.assert_allclose(moves.sum(axis=2), 1.0, atol=1e-12)
            ends = terminal_states(mdp)
            assert len(ends) >= 1
            live_rows = [
                actions for state, actions in enumerate(mdp.table) if state not in set(ends.tolist())
            ]
            assert all(max(len(outcomes) for outcomes in actions) >= 2 for actions in live_rows)
            for actions in mdp.table:
                for outcomes in actions:
                    assert all(done == (int(s) in set(ends.tolist())) for _, s, _, done in outcomes)
            solved = optimal_solution(mdp, beta)
            # value iteration converges well within maxiter (3000) at tol 1e-8, under every reading
            for reading in READINGS:
                _, sweeps = iterate(bellman_sweep(mdp, beta), mdp.n_states, 1e-8, 3000, reading)
                assert sweeps < 1000
            # no tie in the greedy step on the optimal values: a correct student has one answer
            q = np.sort(q_values(mdp, solved.values, beta), axis=1)
            live = np.setdiff1d(np.arange(mdp.n_states), ends)
            assert np.min(q[live, -1] - q[live, -2]) > 1e-6
            # every policy has a finite value (below discount 1): the random ones the checks ask
            draw = seeded_draw(seed, f"policy {case.key}")
            policy_value(mdp, draw.integers(0, mdp.n_actions, mdp.n_states), beta)
    assert {actions for _, actions in sizes} == {4}  # FrozenLake's four actions, as every MDP of the lab
    assert len(sizes) == 9  # every size from 6 to 14 states


def _ends_with_certainty(mdp: Mdp, policy: tuple[int, ...]) -> bool:
    """The absorbing-chain check of one deterministic policy: in the graph of its moves of positive
    probability, every state reaches a terminal state (or a move with no possible outcome, which ends the
    walk: the example's impossible moves). For a finite chain that is exactly "the walk ends with
    probability 1 from every state"; a state that cannot reach one lies in a closed set that never ends."""
    moves = mdp.transitions()[np.arange(mdp.n_states), list(policy)] > 0
    ended = np.zeros(mdp.n_states, dtype=bool)
    ended[terminal_states(mdp)] = True
    ended |= ~moves.any(axis=1)
    while True:
        grown = ended | (moves & ended[np.newaxis, :]).any(axis=1)
        if np.array_equal(grown, ended):
            return bool(ended.all())
        ended = grown


def _every_policy_ends(mdp: Mdp) -> bool:
    """Every deterministic policy checked (the live states' actions enumerated; terminal states' moot)."""
    live = np.setdiff1d(np.arange(mdp.n_states), terminal_states(mdp)).tolist()
    for actions in itertools.product(range(mdp.n_actions), repeat=len(live)):
        policy = [0] * mdp.n_states
        for state, action in zip(live, actions, strict=True):
            policy[state] = action
        if not _ends_with_certainty(mdp, tuple(policy)):
            return False
    return True


def _small_random_mdps() -> list[Mdp]:
    """Random MDPs with at most 6 live states (4**6 policies each), drawn as the held-out ones are."""
    found = []
    for seed in itertools.count():
        mdp = random_mdp(seeded_draw(seed, "small"), "small")
        if mdp.n_states - len(terminal_states(mdp)) <= 6:
            found.append(mdp)
        if len(found) == 6:
            return found
    raise AssertionError("unreachable")


@pytest.mark.slow  # about 30 000 policies checked one by one
def test_every_deterministic_policy_of_the_graders_mdps_ends_its_episodes() -> None:
    """The proof by enumeration: the windy grid and small random MDPs, every policy's chain absorbed."""
    for mdp in (windy_grid(), *_small_random_mdps()):
        assert _every_policy_ends(mdp), mdp.name
        assert trapping_states(mdp).size == 0, mdp.name


@pytest.mark.parametrize(
    ("mdp", "trapped"),
    [
        (lab_example(), [0, 1, 2]),  # right then left: 0 -> 1 -> 0 forever (the lab's own, reward -1 a lap)
        (frozen_lake("4x4", slippery=True), [0, 1, 2, 3]),  # up along the top row: slips stay in it
        (frozen_lake("4x4", slippery=False), [0, 1, 2, 3, 4, 6, 8, 9, 10, 13, 14]),  # into a wall
        (windy_grid(), []),
    ],
    ids=["example", "slippery-lake", "still-lake", "grid"],
)
def test_trapping_states_agree_with_the_absorbing_chain_check(mdp: Mdp, trapped: list[int]) -> None:
    """The fixed point the oracle computes, against the enumeration where some policy is trapped too."""
    assert trapping_states(mdp).tolist() == trapped
    live = [s for s in range(mdp.n_states) if s not in set(terminal_states(mdp).tolist())]
    if len(live) <= 6:
        assert _every_policy_ends(mdp) == (not trapped)
    else:  # the trapping policy the fixed point implies is one the enumeration would find
        moves = mdp.transitions() > 0
        inside = np.zeros(mdp.n_states, dtype=bool)
        inside[trapped] = True
        policy = [0] * mdp.n_states
        for state in trapped:
            policy[state] = next(
                a
                for a in range(mdp.n_actions)
                if moves[state, a].any() and not moves[state, a][~inside].any()
            )
        assert not _ends_with_certainty(mdp, tuple(policy))


@pytest.mark.slow  # 600 random MDPs and every graded case
def test_every_mdp_asked_at_discount_1_lets_every_policy_end_unless_it_is_the_labs_own() -> None:
    """The lab's example and FrozenLake are the lab's own (asked at discount 1 as the lab asks them); every
    MDP of the grader's make asked at discount 1 traps no policy, and every held-out MDP traps none either
    (each move's first outcome leads to a higher state: a ranking that ends every walk)."""
    labs_own = {"the lab's 4-state example", "FrozenLake 4x4 (slippery)", "FrozenLake 8x8 (slippery)"}
    for case in grading_cases():
        assert case.mdp.n_actions == 4
        if case.beta == 1 and case.mdp.name not in labs_own:
            assert trapping_states(case.mdp).size == 0, case.key
    for seed in SEEDS:
        for case in held_out_cases(seed):
            mdp = case.mdp
            assert trapping_states(mdp).size == 0, (seed, case.key)
            ends = set(terminal_states(mdp).tolist())
            for state, actions in enumerate(mdp.table):
                if state in ends:
                    assert all(outcomes == ((1.0, state, 0.0, True),) for outcomes in actions)
                    continue
                for outcomes in actions:
                    assert outcomes[0][0] > 0 and outcomes[0][1] > state
