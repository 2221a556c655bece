"""Errors of grader.classroom: a class download that cannot be read as any layout, or a bad roster."""

from grader.errors import GraderError


class ClassroomError(GraderError, ValueError):
    """Root of the errors raised while recognising a class download, a roster or a gradebook."""


class UnknownLayout(ClassroomError):
    """Raised when ``--layout`` names no layout; the message lists the known ones."""


class LayoutMismatch(ClassroomError):
    """Raised when a download is not of the layout ``--layout`` names (the message says what is missing)."""


class RosterError(ClassroomError):
    """Raised when a roster CSV cannot be read or has no column naming students."""


class GradebookError(ClassroomError):
    """Raised when a gradebook lacks what it needs (e.g. Canvas without an assignment id)."""


class OverridesError(ClassroomError):
    """Raised when an overrides file cannot be read or names what the class has not (every fault listed)."""


class LatePolicyError(ClassroomError):
    """Raised when the configuration's ``[late]`` table, or a file of submission times, is not as expected."""
