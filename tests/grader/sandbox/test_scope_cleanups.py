"""A grading's scope releases what was recorded in it through the cleanup each kind registered."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from grader.sandbox.isolation import scope
from grader.sandbox.isolation.cgroup import CGROUP_RECORDS


def test_importing_the_scope_alone_registers_the_cgroup_cleanup() -> None:
    """The scope imports no layer; the package it lives in does, so no grading closes a scope unaware
    of its cgroups."""
    code = "from grader.sandbox.isolation import scope; print(sorted(scope.CLEANUPS))"
    listed = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=Path.cwd()
    ).stdout
    assert listed.strip() == repr([CGROUP_RECORDS])


def test_closing_a_scope_runs_each_kinds_cleanup_on_what_is_still_recorded(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    released: list[list[str]] = []
    monkeypatch.setitem(scope.CLEANUPS, "test-resources", released.append)
    with scope.sandbox_scope() as variables:
        monkeypatch.setenv(scope.SCOPE_VARIABLE, variables[scope.SCOPE_VARIABLE])
        scope.record("test-resources", "kept", "1 /first")
        scope.record("test-resources", "kept", "2 /second")
        scope.record("test-resources", "released-by-its-owner", "3 /third")
        scope.forget("test-resources", "released-by-its-owner")
        root = Path(os.environ[scope.SCOPE_VARIABLE])
    assert released == [["1 /first", "2 /second"]]
    assert not root.exists()
