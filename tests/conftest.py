"""The suite's skip policy: under `CI=true` a test that skips fails the run unless its skip is declared.

A test skips when what it needs cannot start here (PostgreSQL, Redis, Chromium, an isolation layer). On a
developer's machine that is a notice (`-ra` lists it); under CI, where scripts/setup.sh installed all of
it, a skip means a test that proved nothing, so the run fails and names each one. A skip that is right on
some machines (a Windows-only test on Linux, a root-only one run unprivileged) is declared on its test:

    @pytest.mark.expected_skip("ownership is a POSIX notion")

The marker's text must start the skip's reason, so another skip of the same test still counts.

The default run (a bare `pytest`: the `testpaths` and the mark expression of pyproject's `addopts`) is
distributed over the machine's cores by pytest-xdist (`-n auto` in `addopts`); any other run (`-m ""` as
.ci/run and the README run it, a file or a `-k` of one's own) stays in one process unless it asks for
`-n N` itself. `pytest_xdist_auto_num_workers` below decides.
"""

from __future__ import annotations

import os

import pytest

EXPECTED_SKIP = "expected_skip"
"""The marker that declares a skip expected; its one argument starts the reasons it covers."""

_unexpected: list[tuple[str, str]] = []
"""(node id, reason) of each skip this run did not expect, in the order they happened."""


def under_ci() -> bool:
    """True when the environment says this is a CI run (`CI=true`, as GitHub, GitLab and others set)."""
    return os.environ.get("CI", "").strip().lower() in ("true", "1", "yes")


def _skip_reason(report: pytest.TestReport | pytest.CollectReport) -> str:
    longrepr = report.longrepr
    reason = longrepr[2] if isinstance(longrepr, tuple) else str(longrepr)
    return reason.removeprefix("Skipped: ")


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]) -> pytest.TestReport:
    # Runs where the test ran (an xdist worker too); user_properties travel with the report to the controller.
    report: pytest.TestReport = yield
    if report.skipped and not hasattr(report, "wasxfail"):
        reason = _skip_reason(report)
        for marker in item.iter_markers(EXPECTED_SKIP):
            if reason.startswith(marker.args[0]):
                report.user_properties.append((EXPECTED_SKIP, marker.args[0]))
    return report


def _note(report: pytest.TestReport | pytest.CollectReport) -> None:
    if not report.skipped or hasattr(report, "wasxfail"):
        return
    if any(name == EXPECTED_SKIP for name, _ in getattr(report, "user_properties", ())):
        return
    _unexpected.append((report.nodeid, _skip_reason(report)))


def pytest_runtest_logreport(report: pytest.TestReport) -> None:
    _note(report)


def pytest_collectreport(report: pytest.CollectReport) -> None:
    _note(report)


def pytest_sessionfinish(session: pytest.Session) -> None:
    if under_ci() and _unexpected and not hasattr(session.config, "workerinput"):
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter, config: pytest.Config) -> None:
    if not under_ci() or not _unexpected or hasattr(config, "workerinput"):
        return
    terminalreporter.section("unexpected skips fail a CI run", red=True, bold=True)
    for nodeid, reason in _unexpected:
        terminalreporter.line(f"SKIPPED (unexpected) {nodeid}: {reason}")
    terminalreporter.line(
        f"{len(_unexpected)} test(s) skipped under CI=true: install or start what they need "
        f"(scripts/setup.sh), or declare the skip with "
        f'@pytest.mark.{EXPECTED_SKIP}("<start of its reason>").'
    )


def _default_selection(config: pytest.Config) -> str | None:
    """The mark expression pyproject's `addopts` gives the default run."""
    addopts: list[str] = config.getini("addopts")
    return addopts[addopts.index("-m") + 1] if "-m" in addopts[:-1] else None


@pytest.hookimpl(optionalhook=True)  # xdist's hook: a run without xdist (test_conftest's) has none
def pytest_xdist_auto_num_workers(config: pytest.Config) -> int | None:
    """`-n auto`: xdist's count of the cores for the default run, 0 (one process) for any other."""
    bare = config.args_source is pytest.Config.ArgsSource.TESTPATHS
    if bare and config.option.markexpr == _default_selection(config):
        return None  # xdist's own answer: the machine's cores
    return 0
