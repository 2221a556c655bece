"""tests/conftest.py's skip policy, run on small suites in a fresh pytest: under CI=true an undeclared skip
fails the run and is named; a declared one, an xfail and any skip outside CI do not."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

pytest_plugins = ("pytester",)

CONFTEST = Path(__file__).with_name("conftest.py")

XDIST = ("-p", "xdist.plugin", "-n", "2")
REDIS_MISSING = "test_needs_redis: could not start redis-server: not installed"
NEEDS_REDIS = """
    import pytest

    def test_needs_redis():
        pytest.skip("could not start redis-server: not installed")

    def test_plain():
        assert True
"""
DECLARED = """
    import pytest

    @pytest.mark.expected_skip("ownership is a POSIX notion")
    @pytest.mark.skipif(True, reason="ownership is a POSIX notion")
    def test_windows_only():
        pass
"""
DECLARED_FOR_ANOTHER_REASON = """
    import pytest

    @pytest.mark.expected_skip("already unprivileged")
    def test_as_root():
        pytest.skip("needs a Debian machine with /usr/bin/python3")
"""
XFAIL = """
    import pytest

    @pytest.mark.xfail(reason="known")
    def test_known():
        assert False
"""
MODULE_SKIP = """
    import pytest

    pytest.importorskip("a_module_nobody_has", reason="pip install a_module_nobody_has")

    def test_never_collected():
        pass
"""


@pytest.mark.parametrize(
    ("source", "ci", "extra", "exit_code", "named"),
    [
        (NEEDS_REDIS, "true", (), 1, REDIS_MISSING),
        (NEEDS_REDIS, "true", XDIST, 1, REDIS_MISSING),
        (NEEDS_REDIS, "", (), 0, None),
        (NEEDS_REDIS, "false", (), 0, None),
        (DECLARED, "true", (), 0, None),
        pytest.param(DECLARED, "true", XDIST, 0, None, marks=pytest.mark.slow),  # xdist: slow
        (DECLARED_FOR_ANOTHER_REASON, "true", (), 1, "test_as_root: needs a Debian machine"),
        (XFAIL, "true", (), 0, None),
        (MODULE_SKIP, "true", (), 1, "test_module.py: pip install a_module_nobody_has"),
        pytest.param(MODULE_SKIP, "true", XDIST, 1, "test_module.py: pip install a_module_nobody_has",
                     marks=pytest.mark.slow),  # a worker's collection skip reaches the controller
    ],
    ids=[
        "undeclared-skip-under-ci", "undeclared-skip-under-ci-xdist", "no-ci", "ci-false", "declared",
        "declared-xdist", "declared-for-another-reason", "xfail", "module-level-skip",
        "module-level-skip-xdist",
    ],
)  # fmt: skip
def test_skips_under_ci(
    pytester: pytest.Pytester,
    monkeypatch: pytest.MonkeyPatch,
    source: str,
    ci: str,
    extra: tuple[str, ...],
    exit_code: int,
    named: str | None,
) -> None:
    monkeypatch.setenv("CI", ci)
    monkeypatch.setenv("PYTEST_DISABLE_PLUGIN_AUTOLOAD", "1")  # the installed plugins' start-up, ~10 s a run
    pytester.makeconftest(CONFTEST.read_text(encoding="utf-8"))
    pytester.makepyfile(test_module=textwrap.dedent(source))

    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", *extra)

    assert result.ret == exit_code, result.stdout.str()
    summary = result.stdout.str()
    if named is None:
        assert "unexpected skips fail a CI run" not in summary
    else:
        assert "unexpected skips fail a CI run" in summary
        assert any(line.startswith("SKIPPED (unexpected) test_module.py") and named in line
                   for line in result.stdout.lines), summary  # fmt: skip
        assert "declare the skip with @pytest.mark.expected_skip" in summary


@pytest.mark.parametrize(
    ("arguments", "distributed"),
    [((), True), (("-m", ""), True), (("-m", "not sandbox"), False), (("test_module.py",), False),
     pytest.param(("-k", "plain"), True, marks=pytest.mark.slow),  # each starts an xdist session:
     pytest.param(("-n", "2", "-m", ""), True, marks=pytest.mark.slow)],  # the default run has one
    ids=["bare", "everything", "another-selection", "a-file", "bare-with-k", "asked-for-workers"],
)  # fmt: skip
def test_only_the_default_and_the_full_run_are_distributed_by_n_auto(
    pytester: pytest.Pytester, monkeypatch: pytest.MonkeyPatch, arguments: tuple[str, ...], distributed: bool
) -> None:
    monkeypatch.setenv("PYTEST_DISABLE_PLUGIN_AUTOLOAD", "1")
    pytester.makeconftest(CONFTEST.read_text(encoding="utf-8"))
    pytester.makeini('[pytest]\ntestpaths = .\naddopts = -p xdist.plugin -n auto -m "not slow"\n')
    pytester.makepyfile(test_module="def test_plain():\n    pass\n")

    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", *arguments)

    assert result.ret == 0, result.stdout.str()
    assert ("created: " in result.stdout.str()) == distributed, result.stdout.str()


ALONE_SUITE = """
    import os
    from pathlib import Path

    import pytest

    MARKS = Path(os.environ["MARKS"])

    @pytest.mark.alone("counts the run's workers")
    def test_alone():
        done = sorted(path.name for path in MARKS.glob("done-*"))
        stopped = sorted(path.name for path in MARKS.glob("stopped-*"))
        assert done == [f"done-{n}" for n in range(6)], done
        others = [f"gw{n}" for n in range(2) if f"gw{n}" != os.environ["PYTEST_XDIST_WORKER"]]
        assert stopped == [f"stopped-{worker}" for worker in others], stopped

    @pytest.mark.parametrize("n", range(6))
    def test_plain(n):
        (MARKS / f"done-{n}").touch()
"""
WORKER_STOPS = """

from pathlib import Path


def pytest_sessionfinish(session):  # on a worker: before xdist tells the controller it has finished
    if hasattr(session.config, "workerinput"):
        Path(os.environ["MARKS"], "stopped-" + session.config.workerinput["workerid"]).touch()
"""


@pytest.mark.slow  # starts an xdist session
@pytest.mark.parametrize(
    "arguments", [("-m", ""), ("-n", "2", "-m", "")], ids=["full-run", "asked-for-workers"]
)
def test_an_alone_test_runs_once_every_other_worker_has_stopped(
    pytester: pytest.Pytester, monkeypatch: pytest.MonkeyPatch, arguments: tuple[str, ...]
) -> None:
    marks = pytester.mkdir("marks")
    monkeypatch.setenv("MARKS", str(marks))
    monkeypatch.setenv("PYTEST_DISABLE_PLUGIN_AUTOLOAD", "1")
    monkeypatch.setenv("PYTEST_XDIST_AUTO_NUM_WORKERS", "2")  # xdist's `-n auto` answer, whatever the cores
    pytester.makeconftest(CONFTEST.read_text(encoding="utf-8") + WORKER_STOPS)
    pytester.makeini('[pytest]\ntestpaths = .\naddopts = -p xdist.plugin -n auto -m "not slow"\n'
                     'markers =\n    alone(reason): alone\n')  # fmt: skip
    pytester.makepyfile(test_module=textwrap.dedent(ALONE_SUITE))

    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "-v", *arguments)

    assert result.ret == 0, result.stdout.str()
    result.stdout.fnmatch_lines(["*created: 2/2 workers*"])
    assert result.stdout.lines[-1].startswith("=") and "7 passed" in result.stdout.lines[-1]


def test_an_alone_test_says_why(pytester: pytest.Pytester, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PYTEST_DISABLE_PLUGIN_AUTOLOAD", "1")
    pytester.makeconftest(CONFTEST.read_text(encoding="utf-8"))
    pytester.makeini("[pytest]\nmarkers =\n    alone(reason): alone\n")
    pytester.makepyfile(test_module="import pytest\n\n@pytest.mark.alone\ndef test_x():\n    pass\n")

    result = pytester.runpytest_subprocess("-p", "no:cacheprovider")

    assert result.ret == pytest.ExitCode.USAGE_ERROR, result.stdout.str()
    assert "test_module.py::test_x: @pytest.mark.alone has no reason; expected @pytest.mark.alone(" in (
        result.stderr.str() + result.stdout.str()
    )
