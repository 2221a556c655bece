"""Hostile: allocates (and touches) memory until something gives."""


def bomb():
    hoard = []
    while True:
        hoard.append(b"x" * (64 << 20))


def ok():
    return 42
