"""Hostile: ignores SIGTERM (and SIGINT) and sleeps forever in small steps."""

import signal
import time


def stubborn():
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    while True:
        time.sleep(0.01)


def ok():
    return 42
