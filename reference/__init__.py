"""Reference solutions and exact oracles for the OpenGym AI lab.

The contract other parts rely on:

- `reference/solutions.py`: `random_blackjack(n)`, `blackjack(n=11)`, `cartpole()`, `car()`,
  `find_qvalues(env, alpha=.1, gamma=.6, epsilon=.1)`, `taxi(q_table=None)` on gymnasium 1.4's API.
- `reference/oracles/blackjack.py` (pure, exact):
  - `evaluate_policy(hit_probability, *, sab=False) -> Outcome` where
    `hit_probability(player_sum: int, dealer_card: int, usable_ace: bool) -> float` and
    `Outcome(win: float, draw: float, loss: float)` (frozen dataclass; `expected_reward = win - loss`).
  - `random_policy_outcome(*, sab=False) -> Outcome`; `threshold_policy_outcome(n, *, sab=False) -> Outcome`
    ("hit while observed player sum <= n", n = 0..21).
- `reference/oracles/taxi.py` (pure, exact; Taxi-v3 == Taxi-v4 defaults, 200-step limit):
  - `ReturnMoments(mean: float, variance: float)` of the total episode reward from the reset distribution.
  - `random_policy_return(max_steps=200) -> ReturnMoments`
  - `optimal_q_table(gamma=0.6) -> np.ndarray` shape (500, 6), value iteration.
  - `greedy_policy_return(q_table, max_steps=200) -> ReturnMoments` (greedy = `np.argmax(q_table[s])`,
    first index on ties, exactly what the lab's loop does).
  - `optimal_return(max_steps=200) -> ReturnMoments` (best achievable undiscounted return within
    the limit, finite-horizon DP); bad input raises `reference.errors.InvalidQTableError` /
    `InvalidParameterError` (both `ValueError`s; root `reference.errors.ReferencePackageError`).
- Keyword-only options of the solutions: `seed=None` on every function,
  `games=10_000` on `blackjack`, `episodes=` on `find_qvalues` (100 000) and `taxi` (10 000).
  Win rates are fractions in [0, 1].
- `reference/oracles/guessing_game.py` (pure, exact rationals): `midpoint_guess_counts(low=-1000, high=1000)
  -> GuessCounts(probabilities)` (`probabilities[k-1]` = P(k guesses); `mean`, `variance`, `most`,
  `probability(k)`), the guess-count distribution of a midpoint search from [low, high] in
  `GuessingGame-v0`, whose rules it restates (`TARGET_LOW/HIGH`, `TOLERANCE`, `MAX_GUESSES`; a test
  pins them to `grader.compat`'s env). Solution: `guessing_game(*, seed=None) -> int` (the optional
  problem; needs `GuessingGame-v0` registered, e.g. by `grader.compat.register_envs()`).
- `python -m reference.oracles --json` prints all of them (built by `reference/oracles/table.py`).
"""
