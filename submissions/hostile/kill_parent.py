"""Hostile: signals its parent and every process it can (kill -1)."""

import os
import signal


def kill():
    refused = 0
    for target in (os.getppid(), 1):
        try:
            os.kill(target, signal.SIGKILL)
        except PermissionError:
            refused += 1
    try:
        os.kill(-1, signal.SIGKILL)
    except OSError:
        pass
    return refused


def ok():
    return 42
