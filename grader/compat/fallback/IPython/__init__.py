"""Stand-in for IPython when it is not installed: just enough for `from IPython.display import clear_output`.

The layer appends its directory to the end of `sys.path`, so an installed IPython always wins.
"""

from . import display

__all__ = ["display"]
