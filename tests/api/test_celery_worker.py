"""The Celery worker's start-up checks and its split of the cores, without a broker."""

from __future__ import annotations

import pytest
from api_testing import SettingsFactory

from api.jobs import celery_worker
from api.jobs.celery_worker import split_cores, startup_problem
from grader.render.neutral import MAX_FILE_NAME_CHARS, file_name
from grader.sandbox import IsolationReport, LayerReport


@pytest.mark.parametrize(
    ("cores", "concurrency", "grading_workers", "expected"),
    [
        (2, None, None, (2, 1)),
        (2, 1, None, (1, 2)),
        (8, 4, None, (4, 2)),
        (8, 3, 1, (3, 1)),
        (1, 4, None, (4, 1)),
    ],
    ids=[
        "a-grading-per-core",
        "one-grading-all-cores",
        "four-of-eight",
        "explicit-grading-workers",
        "never-zero",
    ],
)
def test_cores_are_split_between_gradings_and_their_xdist_workers(
    monkeypatch: pytest.MonkeyPatch,
    make_settings: SettingsFactory,
    cores: int,
    concurrency: int | None,
    grading_workers: int | None,
    expected: tuple[int, int],
) -> None:
    monkeypatch.setattr(celery_worker, "cores", lambda: cores)
    settings = make_settings(grading_workers=grading_workers)
    assert split_cores(concurrency, settings) == expected


def test_a_worker_refuses_a_machine_that_cannot_isolate(
    monkeypatch: pytest.MonkeyPatch, make_settings: SettingsFactory
) -> None:
    missing = LayerReport(
        name="bubblewrap",
        active=False,
        detail="bubblewrap (bwrap) is not installed",
        remedy="apt-get install bubblewrap",
        required=True,
    )
    monkeypatch.setattr(celery_worker, "broker_problem", lambda settings: None)
    monkeypatch.setattr("grader.sandbox.probe_isolation", lambda: IsolationReport(layers=(missing,)))
    problem = startup_problem(make_settings(broker_url="redis://127.0.0.1:1/0"))
    assert problem == (
        "this machine cannot isolate submissions as grading requires: bubblewrap: bubblewrap (bwrap) is not "
        "installed (apt-get install bubblewrap). Install the missing layers (see scripts/setup.sh), or set "
        "GYMGRADE_ALLOW_WEAK_ISOLATION=1 for a trial only"
    )
    assert (
        startup_problem(make_settings(broker_url="redis://127.0.0.1:1/0", allow_weak_isolation=True)) is None
    )


@pytest.mark.parametrize(
    ("exitcode", "stop_requested", "restarts", "expected"),
    [
        (1, False, 0, True),
        (1, False, 4, True),
        (1, False, 5, False),
        (1, True, 0, False),
        (0, False, 0, False),
        (None, False, 0, False),
    ],
    ids=["crashed", "crashed-fifth-time", "crashed-too-often", "asked-to-stop", "clean-exit", "no-exit-code"],
)
def test_a_worker_restarts_in_place_only_after_a_crash_it_was_not_asked_for(
    exitcode: int | None, stop_requested: bool, restarts: int, expected: bool
) -> None:
    history = tuple(float(moment) for moment in range(restarts))
    assert celery_worker.should_restart(exitcode, stop_requested, history) is expected


def test_the_restart_history_keeps_the_window_and_ignores_garbage() -> None:
    now = 10_000.0
    window = celery_worker.RESTART_WINDOW_SECONDS
    variable = f"{now - window - 1},{now - 10},x,,{now + 5},{now}"
    assert celery_worker.restart_history(variable, now) == (now - 10, now)
    assert celery_worker.restart_history(None, now) == ()


@pytest.mark.parametrize(
    ("name", "filename", "shown"),
    [
        ("smithjohn_3001_7001_policy_iteration-1.py", "6.py", "smithjohn_3001_7001_policy_iteration-1.py"),
        ("'=cmd.py", "6.py", "'=cmd.py"),
        ("=cmd.py", "6.py", "'=cmd.py"),
        ("../../etc/passwd.py", "6.py", "passwd.py"),
        ("a\x1b]0;owned\x07\u202eb.py", "6.py", "a\ufffd]0;owned\ufffd\ufffdb.py"),
        ("x" * 100_000, "6.py", "x" * (MAX_FILE_NAME_CHARS - 1) + "…"),
        (None, "6.py", "6.py"),
        ("", "../evil.py", "evil.py"),
        (["a.py"], "6.py", "6.py"),
    ],
    ids=[
        "lms-name",
        "already-neutralised",
        "formula",
        "climbing",
        "controls-and-bidi",
        "huge",
        "no-field",
        "empty",
        "not-text",
    ],
)
def test_a_requests_name_is_shown_as_file_name_shows_it(name: object, filename: str, shown: str) -> None:
    """The batch sends ``file_name`` of the download's name; the worker, trusting no request, applies it
    again (a no-op on what the batch sent) and falls back on the request's ``filename``."""
    assert celery_worker.shown_name(name, filename) == shown
    assert file_name(shown) == shown
