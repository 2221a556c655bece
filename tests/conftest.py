"""The suite's skip policy: under `CI=true` a test that skips fails the run unless its skip is declared.

A test skips when what it needs cannot start here (PostgreSQL, Redis, Chromium, an isolation layer). On a
developer's machine that is a notice (`-ra` lists it); under CI, where scripts/setup.sh installed all of
it, a skip means a test that proved nothing, so the run fails and names each one. A skip that is right on
some machines (a Windows-only test on Linux, a root-only one run unprivileged) is declared on its test:

    @pytest.mark.expected_skip("ownership is a POSIX notion")

The marker's text must start the skip's reason, so another skip of the same test still counts.

The suite's distribution: the default run (a bare `pytest`: the `testpaths` and the mark expression of
pyproject's `addopts`) and the full run (a bare `pytest -m ""`, as .ci/run and the README run it) are spread
over the machine's cores by pytest-xdist (`-n auto` in `addopts`); any other run (a file, another `-m` or a
`-k` of one's own) stays in one process unless it asks for `-n N` itself. `pytest_xdist_auto_num_workers`
below decides.

Every distributed run but the default one is scheduled by `AloneLastScheduling`: xdist's `loadgroup` (a
test at a time to whichever worker is free; the tests of one `xdist_group` on one worker, for a module
fixture too heavy to build once per worker) followed by the tests that must not share the machine, each
declared with its reason:

    @pytest.mark.alone("sends SIGINT to its own process and times the session's reaction")

Those run last, one after the other on one worker, once every other worker has stopped. (The default run
keeps xdist's `load`: none of its tests is marked `alone`, and it has no heavy fixture to share.)
"""

from __future__ import annotations

import os

import pytest

try:  # the scheduler is xdist's; a run without xdist (test_conftest's subprocesses) has none and needs none
    from xdist.scheduler import LoadGroupScheduling
except ImportError:  # pragma: no cover
    LoadGroupScheduling = object  # type: ignore[assignment,misc]

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


def _is_default_run(config: pytest.Config) -> bool:
    bare = config.args_source is pytest.Config.ArgsSource.TESTPATHS
    return bare and config.option.markexpr == _default_selection(config)


def _is_full_run(config: pytest.Config) -> bool:
    return config.args_source is pytest.Config.ArgsSource.TESTPATHS and config.option.markexpr == ""


@pytest.hookimpl(optionalhook=True)  # xdist's hook: a run without xdist (test_conftest's) has none
def pytest_xdist_auto_num_workers(config: pytest.Config) -> int | None:
    """`-n auto`: xdist's count of the cores for the default run and the full run, 0 for any other."""
    if _is_default_run(config) or _is_full_run(config):
        return None  # xdist's own answer: the machine's cores
    return 0


ALONE = "alone"
"""The marker of a test that must not share the machine with another test; its one argument says why."""

ALONE_GROUP = "alone"
"""The xdist group the `alone` tests join on a worker, so that `AloneLastScheduling` can tell them."""


def pytest_configure(config: pytest.Config) -> None:
    # On the controller, before xdist starts its workers: xdist's default `load` becomes `loadgroup`, which
    # AloneLastScheduling extends, for every run but the default. A worker parses the command line afresh
    # (`--dist` is not on it), so it learns of `loadgroup`, which names the groups in its node ids, from its
    # workerinput (pytest_configure_node).
    workerinput = getattr(config, "workerinput", None)
    if workerinput is not None:
        if workerinput.get(ALONE_GROUP):
            config.option.loadgroup = True
    elif getattr(config.option, "dist", "no") == "load" and not _is_default_run(config):
        config.option.dist = "loadgroup"


@pytest.hookimpl(optionalhook=True)  # xdist's hook, on the controller, for each worker it starts
def pytest_configure_node(node: object) -> None:
    config: pytest.Config = node.config  # type: ignore[attr-defined]
    node.workerinput[ALONE_GROUP] = getattr(config.option, "dist", "no") == "loadgroup"  # type: ignore[attr-defined]


@pytest.hookimpl(tryfirst=True)  # before xdist's worker names each test's groups in its node id
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        marker = item.get_closest_marker(ALONE)
        if marker is None:
            continue
        if not marker.args or not str(marker.args[0]).strip():
            raise pytest.UsageError(
                f"{item.nodeid}: @pytest.mark.{ALONE} has no reason; expected "
                f'@pytest.mark.{ALONE}("<why this test cannot share the machine>")'
            )
        item.add_marker(pytest.mark.xdist_group(ALONE_GROUP), append=False)


def _is_alone(scope: str) -> bool:
    return ALONE_GROUP in scope.split("_")


class AloneLastScheduling(LoadGroupScheduling):  # type: ignore[misc,valid-type]
    """xdist's `loadgroup`, then the `alone` tests on one worker once every other worker has stopped.

    A worker starts a test only once it holds the next one (pytest tears fixtures down knowing what comes
    next), so the `alone` tests cannot simply wait in a worker's queue: once nothing but them is left, the
    first worker asking for work becomes their runner and gets nothing yet, every other worker is told to
    shut down (it runs what it holds and stops), and the runner receives the `alone` tests when the last of
    the others has stopped. Follows xdist's `Scheduling` protocol, as its `LoadScopeScheduling` does.
    """

    def __init__(self, config: pytest.Config, log: object | None = None) -> None:
        super().__init__(config, log)
        self._runner: object | None = None

    def _split_scope(self, nodeid: str) -> str:
        scope: str = super()._split_scope(nodeid)
        return ALONE_GROUP if "@" in nodeid and _is_alone(scope) else scope

    def _only_alone_left(self) -> bool:
        return len(self.workqueue) == 1 and ALONE_GROUP in self.workqueue

    def _assign_work_unit(self, node: object) -> None:
        if ALONE_GROUP in self.workqueue and len(self.workqueue) > 1:
            self.workqueue.move_to_end(ALONE_GROUP)
        if not self._only_alone_left():
            super()._assign_work_unit(node)
            return
        if self._runner is None:
            self._runner = node
        for other in self.nodes:
            if other is not self._runner and not other.shutting_down:
                other.shutdown()
        self._start_alone()

    def _start_alone(self) -> None:
        if self._runner is not None and self._only_alone_left() and self.nodes == [self._runner]:
            super()._assign_work_unit(self._runner)

    def mark_test_complete(self, node: object, item_index: int, duration: float = 0) -> None:
        super().mark_test_complete(node, item_index, duration)
        # A finished group leaves the worker's books: loadscope sums every group a worker ever had at each
        # event, which a run of 4,000 single-test groups would pay some millions of times.
        scope = self._split_scope(self.registered_collections[node][item_index])
        assigned = self.assigned_work.get(node, {})
        work = assigned.get(scope)
        if work is not None and all(work.values()):
            del assigned[scope]

    def remove_node(self, node: object) -> str | None:
        crashitem: str | None = super().remove_node(node)  # a crashed worker's tests go back in the queue
        if node is self._runner:
            self._runner = None  # crashed: the next worker to ask becomes the runner
        self._start_alone()
        return crashitem


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: object) -> AloneLastScheduling | None:
    """`AloneLastScheduling` for a `loadgroup` run (see pytest_configure); xdist's own otherwise."""
    if getattr(config.option, "dist", "no") != "loadgroup":
        return None
    return AloneLastScheduling(config, log)
