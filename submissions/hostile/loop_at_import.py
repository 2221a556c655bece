"""Hostile: never finishes importing."""

while True:
    pass


def ok():
    return 42
