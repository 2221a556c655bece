"""gymgrade: the grader for the OpenGym AI lab."""

__version__ = "0.1.0"
