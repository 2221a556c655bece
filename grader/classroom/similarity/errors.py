"""Errors of the similarity check's own inputs (a student's unreadable file is a listed reason instead)."""

from grader.errors import GraderError


class SimilarityError(GraderError):
    """Root of every error the similarity check raises."""


class ClassDirectoryError(SimilarityError, ValueError):
    """Raised when the class directory (or a --reference directory) does not exist or is not a directory."""


class TemplateError(SimilarityError, ValueError):
    """Raised when a template file given with --template cannot be read or parsed as Python."""
