"""Hostile: prints 100 MB to stdout."""

import sys


def flood():
    line = "A" * 1023 + "\n"
    block = line * 1024
    for _ in range(100):
        sys.stdout.write(block)
    return 1


def ok():
    return 42
