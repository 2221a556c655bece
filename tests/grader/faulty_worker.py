"""A pytest plugin for the acceptance session's workers that fails one case on purpose (a test double).

Loaded with ``run_session(..., plugins=["faulty_worker"])``; the variables it reads are set by the test:
``GYMGRADE_TEST_CRASH_CASE`` names the node id whose worker dies in the middle of the check (``os._exit``),
``GYMGRADE_TEST_NO_ISOLATION`` makes every check find that isolation is unavailable.
"""

from __future__ import annotations

import os

import pytest

from grader.sandbox.errors import IsolationUnavailable

CRASH_CASE = "GYMGRADE_TEST_CRASH_CASE"
NO_ISOLATION = "GYMGRADE_TEST_NO_ISOLATION"


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_call(item: pytest.Item) -> None:
    if hasattr(item.config, "workerinput") and item.nodeid == os.environ.get(CRASH_CASE):
        os._exit(3)


def pytest_configure(config: pytest.Config) -> None:
    if hasattr(config, "workerinput") and os.environ.get(NO_ISOLATION):
        import grader.grading.execution

        def refuse(*args: object, **kwargs: object) -> None:
            raise IsolationUnavailable("test double: this worker cannot isolate")

        grader.grading.execution.run_problem = refuse  # type: ignore[assignment]
