"""Hostile: writes thousands of 1 MB files into the scratch directory."""

import os


def fill():
    chunk = b"\1" * (1 << 20)
    home = os.path.expanduser("~")
    for number in range(5000):
        with open(os.path.join(home, f"file{number}.bin"), "wb") as stream:
            stream.write(chunk)
    return 5000


def ok():
    return 42
