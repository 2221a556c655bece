"""The held-out random MDPs a grading seed adds (`reference.oracles.mdps.held_out_cases`) are well posed for
every pure problem, the same for the same seed and different for another."""

from __future__ import annotations

import numpy as np
import pytest

from grader.lab.rl2.checks.mdp_calls import READINGS, bellman_sweep, iterate
from reference.oracles.mdp import optimal_solution, policy_value, q_values, terminal_states
from reference.oracles.mdps import HELD_OUT, grading_cases, held_out_cases, seeded_draw

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
    assert len(sizes) > 10  # varied sizes
