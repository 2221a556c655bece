"""`IPython.display.clear_output` and `display` outside a notebook, without IPython installed."""

from __future__ import annotations

from typing import Any


def clear_output(wait: bool = False) -> None:
    """Do nothing: outside a notebook there is no output cell to clear.

    Args:
        wait: accepted for compatibility (IPython waits for new output before clearing).
    """


def display(*objs: Any, **kwargs: Any) -> None:
    """Print the objects, as IPython's `display` does outside a notebook.

    Args:
        *objs: the objects to show.
        **kwargs: accepted for compatibility (IPython's display options); ignored.
    """
    print(*objs)
