"""Template-aware code similarity across a class and against known solutions, ranked for a person to read.

It never changes a grade and never accuses: a flagged pair is a pair whose code shares more than
independent solutions of this lab share, with the matched code shown side by side.
"""
