"""Hostile: forks sleeping children until fork fails (bounded: at most 500)."""

import os
import time


def bomb():
    children = 0
    try:
        for _ in range(500):
            if os.fork() == 0:
                time.sleep(300)
                os._exit(0)
            children += 1
    except OSError:
        pass
    return children


def ok():
    return 42
