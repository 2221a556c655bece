"""Errors raised by the grader's own code (never by a student's submission, whose failures are data), and the
exit statuses the commands end with."""

EXIT_FULL_MARKS, EXIT_NOT_FULL, EXIT_ERROR = 0, 1, 2
"""`gymgrade check`: every problem passed; not every problem passed; the grading could not be done (a
missing file, a bad configuration, a grader error). `gymgrade grade` ends 0 or EXIT_ERROR."""
EXIT_INTERRUPTED = 130
"""A command stopped by Ctrl-C or SIGTERM (128 + SIGINT): what finished is kept."""


class GraderError(Exception):
    """Root of every error raised by the `grader` package outside its subpackages."""


class ConfigError(GraderError, ValueError):
    """Raised when the assignment configuration file is missing, not TOML, or has an invalid field."""


class PlanError(GraderError, ValueError):
    """Raised when a problem gets settings of another problem's model, or settings never loaded for one."""


class UnknownProblem(GraderError, ValueError):
    """Raised when a problem id (e.g. in `--only`) is none of the registry's; the message lists them."""


class ExecutorUnavailable(GraderError):
    """Raised when a configured batch executor (e.g. the distributed one) cannot be reached or used."""


class BatchInterrupted(KeyboardInterrupt):
    """Raised when a batch is interrupted (Ctrl-C, SIGTERM); says how much of it is kept in its directory.

    Args:
        finished: Files whose report is in the output directory (reused or graded by this run).
        total: Files in the batch.
    """

    def __init__(self, finished: int, total: int) -> None:
        super().__init__(f"{finished} of {total} submissions graded")
        self.finished = finished
        self.total = total


class GradescopeError(GraderError, ValueError):
    """Raised when a Gradescope file (an autograder zip, an upload's submission metadata) cannot be used."""
