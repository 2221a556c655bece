"""The `serve` and `worker` subcommands: entry-point registration, arguments, refusal of bad settings."""

from __future__ import annotations

import argparse
from importlib.metadata import entry_points

import pytest

from api.commands import add_serve_command, add_worker_command


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="gymgrade")
    subparsers = parser.add_subparsers(dest="command", required=True)
    add_serve_command(subparsers)
    add_worker_command(subparsers)
    return parser


def test_the_commands_are_registered_in_the_entry_point_group() -> None:
    registered = {entry.name: entry.value for entry in entry_points(group="gymgrade.commands")}
    assert registered["serve"] == "api.commands:add_serve_command"
    assert registered["worker"] == "api.commands:add_worker_command"


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["serve"], {"host": "127.0.0.1", "port": 8000}),
        (["serve", "--host", "0.0.0.0", "--port", "9000"], {"host": "0.0.0.0", "port": 9000}),
        (["worker"], {"workers": None}),
        (["worker", "--workers", "3"], {"workers": 3}),
    ],
    ids=["serve-defaults", "serve-options", "worker-defaults", "worker-options"],
)
def test_arguments_are_parsed(argv: list[str], expected: dict[str, object]) -> None:
    args = _parser().parse_args(argv)
    assert callable(args.handler)
    assert {name: getattr(args, name) for name in expected} == expected


@pytest.mark.parametrize("command", ["serve", "worker"])
def test_unsafe_settings_stop_the_command_with_status_2(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    monkeypatch.setenv("GYMGRADE_INSTRUCTOR_TOKEN", "password")
    monkeypatch.delenv("GYMGRADE_DEVELOPMENT", raising=False)
    args = _parser().parse_args([command])
    assert args.handler(args) == 2
    assert (
        "GYMGRADE_INSTRUCTOR_TOKEN is weak: expected at least 24 characters, found 8"
        in capsys.readouterr().err
    )


def test_worker_refuses_a_pool_of_zero(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setenv("GYMGRADE_DEVELOPMENT", "1")
    args = _parser().parse_args(["worker", "--workers", "0"])
    assert args.handler(args) == 2
    assert "--workers must be at least 1, found 0" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("variable", "value", "message"),
    [
        (
            "GYMGRADE_MAX_UPLOAD_BYTES",
            "-3",
            "GYMGRADE_MAX_UPLOAD_BYTES: Input should be greater than 0, found '-3'",
        ),
        (
            "GYMGRADE_GRADEBOOK_POLICY",
            "worst",
            "GYMGRADE_GRADEBOOK_POLICY: Input should be 'latest' or 'best', found 'worst'",
        ),
    ],
    ids=["negative-upload-limit", "unknown-gradebook-policy"],
)
def test_invalid_settings_name_the_variable_and_the_value(
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    variable: str,
    value: str,
    message: str,
) -> None:
    monkeypatch.setenv("GYMGRADE_DEVELOPMENT", "1")
    monkeypatch.setenv(variable, value)
    args = _parser().parse_args(["serve"])
    assert args.handler(args) == 2
    assert capsys.readouterr().err == f"gymgrade: {message}\n"


@pytest.mark.parametrize(
    ("grader", "message"),
    [
        (
            "no_such_module:grade",
            "GYMGRADE_GRADER names module 'no_such_module', which is not installed; "
            "expected e.g. grader.grading.grade:grade_submission",
        ),
        (
            "grader.grading.grade",
            "GYMGRADE_GRADER must look like module:function, found 'grader.grading.grade'",
        ),
    ],
    ids=["missing-module", "no-function"],
)
@pytest.mark.parametrize("command", ["serve", "worker"])
def test_an_unusable_grader_stops_the_command_at_start(
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    command: str,
    grader: str,
    message: str,
) -> None:
    monkeypatch.setenv("GYMGRADE_DEVELOPMENT", "1")
    monkeypatch.setenv("GYMGRADE_GRADER", grader)
    args = _parser().parse_args([command])
    assert args.handler(args) == 2
    assert capsys.readouterr().err == f"gymgrade: {message}\n"
