"""Grading jobs: the queue protocol, its backends, and the worker pool that runs gradings."""
