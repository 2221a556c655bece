"""Hostile: a function that never returns."""


def spin():
    while True:
        pass


def ok():
    return 42
