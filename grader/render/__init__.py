"""Output formats of a grading: one module per format, chosen by name from `grader.render.registry`."""
