"""Simulated students for tests and calibration; never used when grading.

`grader.simulated_students.simulation` runs student-like functions in-process on gymnasium and builds the
`CallRecord`s the sandbox and the replay would (no processes, no isolation);
`grader.simulated_students.behaviours` holds the reference's policies and the typical mistakes as such
functions. The checks' tests and `bench/calibrate.py` / `bench/versions.py` judge them with the real checks.
Nothing on the grading path imports this package (tests/grader/simulated_students/test_boundaries.py holds
that).
"""
