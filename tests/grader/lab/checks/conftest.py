"""Fixtures of the checks' tests."""

import zlib

import pytest


@pytest.fixture
def seed(request: pytest.FixtureRequest) -> int:
    """A seed derived from the test's identity (the same under -n 0 and -n 2, and wherever the file sits: its
    name and the test's, not its folder)."""
    return zlib.crc32(request.node.nodeid.rpartition("/")[2].encode())
