"""Hostile: writes a 1 GB file into the scratch directory."""

import os
import tempfile


def fill():
    chunk = b"\0" * (1 << 20)
    with open(os.path.join(tempfile.gettempdir(), "big.bin"), "wb") as stream:
        for _ in range(1024):
            stream.write(chunk)
    return 1024


def ok():
    return 42
