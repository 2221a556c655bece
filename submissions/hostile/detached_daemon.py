"""Hostile: leaves a detached daemon (double fork + setsid) running after the call returns."""

import os
import time


def detach():
    if os.fork() == 0:
        os.setsid()
        if os.fork() == 0:
            while True:
                time.sleep(0.05)
        os._exit(0)
    os.wait()
    return "detached"


def ok():
    return 42
