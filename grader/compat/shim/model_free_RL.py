"""`model_free_RL`: the second lab's helper module under the template's name (grader/compat/model_free.py)."""

from grader.compat.model_free import Q_TABLE_FILE, epsilon_decay, run_qlearn, run_simulation_table

__all__ = ["Q_TABLE_FILE", "epsilon_decay", "run_qlearn", "run_simulation_table"]
