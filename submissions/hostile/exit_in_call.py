"""Hostile: ends the process from inside a call (sys.exit(0) and os._exit(0))."""

import os
import sys


def sys_exit():
    sys.exit(0)


def os_exit():
    os._exit(0)


def ok():
    return 42
