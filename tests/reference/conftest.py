"""Fixtures for the reference tests: seeds derived from each test's identity."""

from __future__ import annotations

import zlib

import pytest


@pytest.fixture
def seed(request: pytest.FixtureRequest) -> int:
    """A seed fixed by the test's node id, so a run alone, in any order or under xdist is reproducible."""
    return zlib.crc32(request.node.nodeid.rpartition("/")[2].encode())  # its name, not its folder
