"""Hostile: ends the process with os._exit(0) while being imported.

Its functions read what the exiting statement sets, so a grading runs that statement at import (a `.py`'s
top level is read as a notebook's, but what its functions use runs at import, as a `.py` always did).
"""

import os

EXITED = os._exit(0)


def random_blackjack(n):
    return EXITED


def car():
    return EXITED
