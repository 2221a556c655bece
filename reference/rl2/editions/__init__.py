"""The second lab's reference solution in each edition's names, signatures and return shapes.

One module per edition, each defining exactly the functions its edition asks for, on
`reference.rl2.solutions`:

- `v2018` (2018, gym 0.10): `extract_policy`, `compute_policy_v`, `frozenlake(basic_case, M)` (five
  results), `run_simulation(env, policy, beta)`;
- `v2019` (2019-2022, gym): the same, `frozen_lake(basic_case, M, render)`,
  `run_simulation(env, policy, render, beta)`;
- `v2023` (2023, gymnasium): the same names, `run_simulation(env, policy, beta)`;
- `v2024` (2024): `policy_improvement`, `iter_policy_eval`, `frozen_lake` with six results,
  `model_comparison`;
- `v2026` (the 2026 template): the 2024 names without `model_comparison`.
"""

EDITIONS = ("v2018", "v2019", "v2023", "v2024", "v2026")
"""The editions, oldest first (module names under `reference.rl2.editions`)."""
