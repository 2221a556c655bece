"""`gymgrade check` chooses the edition (flag, configuration or detection), says which and why, grades it."""

import json
import zipfile
from pathlib import Path

import pytest

from grader import cli
from grader.editions import EDITIONS
from grader.report import Report

RL1 = EDITIONS["rl1"]
CLASSIC_COMPLETE = EDITIONS["classic"].reference


def test_the_rl1_template_is_detected_and_its_epsilon_decay_is_missing(
    capsys: pytest.CaptureFixture[str],
) -> None:
    argv = ["check", str(RL1.template), "--only", "epsilon_decay", "--format", "json", "--workers", "1"]
    assert cli.main(argv) == cli.EXIT_NOT_FULL
    captured = capsys.readouterr()
    assert (
        "Edition: rl1 (Reinforcement Learning 1: Gymnasium): detected from rl1.py: it defines epsilon_decay("
        in captured.err
    )
    (result,) = json.loads(captured.out)["problems"]
    assert (result["id"], result["status"]) == ("epsilon_decay", "missing")
    assert "not attempted yet" in result["feedback"]


def test_a_problem_the_detected_edition_does_not_grade_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["check", str(CLASSIC_COMPLETE), "--only", "epsilon_decay"]) == cli.EXIT_ERROR
    err = capsys.readouterr().err
    assert "Edition: classic (OpenGym AI (classic gym)): detected from classic_complete.py" in err
    assert (
        "unknown problem epsilon_decay; expected ids among random_blackjack, blackjack, cartpole, car, taxi"
        in err
    )


def test_a_flag_against_the_configuration_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    config = EDITIONS["classic"].default_config
    argv = ["check", str(RL1.template), "--edition", "rl1", "--config", str(config)]
    assert cli.main(argv) == cli.EXIT_ERROR
    assert (
        f"--edition rl1 grades {', '.join(RL1.registry.ids)}, but {config}"
        in capsys.readouterr().err
    )


def test_the_edition_flag_lists_every_edition(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        cli.build_parser().parse_args(["check", "x.py", "--edition", "rl9"])
    assert "choose from classic, gym026, volume2, rl1" in capsys.readouterr().err.replace("'", "")


def test_grade_without_edition_or_configuration_detects_it_per_submission(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    inputs = tmp_path / "inputs"
    for student, source in (("alice", RL1.reference), ("bob", RL1.template), ("carol", CLASSIC_COMPLETE)):
        (inputs / student).mkdir(parents=True)
        (inputs / student / "opengym.py").write_bytes(source.read_bytes())
    out = tmp_path / "out"
    argv = ["grade", str(inputs), "--out", str(out), "--only", "epsilon_decay", "--workers", "1"]
    assert cli.main(argv) == 0
    err = capsys.readouterr().err
    assert "Edition: rl1 (Reinforcement Learning 1: Gymnasium): detected per submission" in err
    assert "  alice: rl1: it defines epsilon_decay(" in err
    assert "  carol: classic: " in err and "graded as rl1 with the class" in err
    reports = {path.stem: Report.model_validate_json(path.read_text()) for path in out.glob("*.json")}
    assert {student: report.edition for student, report in reports.items()} == {
        "alice": "rl1", "bob": "rl1", "carol": "rl1"
    }  # fmt: skip
    statuses = {student: report.problems[0].status for student, report in reports.items()}
    assert statuses == {"alice": "passed", "bob": "missing", "carol": "missing"}


def test_grade_with_a_configuration_says_its_edition_and_detects_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["grade", str(tmp_path), "--out", str(tmp_path / "out"), "--config", str(RL1.default_config)]
    args = cli.build_parser().parse_args(argv)
    cli._choose_edition(args)
    assert args.config == RL1.default_config and not getattr(args, "detect_editions", False)
    assert f"Edition: rl1 (Reinforcement Learning 1: Gymnasium): named by {RL1.default_config}" in (
        capsys.readouterr().err
    )


def test_the_gradescope_bundle_carries_the_editions_configuration(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bundle = tmp_path / "autograder.zip"
    assert cli.main(["gradescope-bundle", "--edition", "rl1", "--out", str(bundle)]) == 0
    assert "Edition: rl1" in capsys.readouterr().err
    with zipfile.ZipFile(bundle) as archive:
        assert archive.read("assignment.toml") == RL1.default_config.read_bytes()
