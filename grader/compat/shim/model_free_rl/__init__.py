"""`model_free_rl`: the helper module under the name the 2024 lab text gives it (`run_q_learn`).

The same functions as `model_free_RL` (the template's name, `run_qlearn`), from grader/compat/model_free.py;
a package rather than a second file so that the two names do not collide on a case-insensitive file system.
"""

from grader.compat.model_free import Q_TABLE_FILE, epsilon_decay, run_qlearn, run_simulation_table

run_q_learn = run_qlearn
"""The 2024 lab text's name for `run_qlearn`."""

__all__ = ["Q_TABLE_FILE", "epsilon_decay", "run_q_learn", "run_qlearn", "run_simulation_table"]
