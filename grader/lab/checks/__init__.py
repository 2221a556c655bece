"""Per-problem checks: each module declares a problem's settings model and its check (pure, no I/O).

`grader.lab.problems` pairs each with its problem id; `base.py` is the contract they follow.
"""
