"""Jupyter notebooks as submissions: the graded module built from their code cells, in bounded time and
memory (see `grader.submission.notebook.building` for what is kept, `grader.submission.notebook.bounded` for
the bounds)."""

from __future__ import annotations

from grader.submission.notebook.bounded import build_module, read_notebook
from grader.submission.notebook.models import NotebookModule, NotebookSummary, SkippedCode, UnboundGlobal
from grader.submission.notebook.reading import MAX_NOTEBOOK_BYTES

NOTEBOOK_SUFFIX = ".ipynb"


def is_notebook(name: str) -> bool:
    """True when a submission's file name says it is a Jupyter notebook."""
    return name.lower().endswith(NOTEBOOK_SUFFIX)


__all__ = [
    "MAX_NOTEBOOK_BYTES",
    "NOTEBOOK_SUFFIX",
    "NotebookModule",
    "NotebookSummary",
    "SkippedCode",
    "UnboundGlobal",
    "build_module",
    "is_notebook",
    "read_notebook",
]
