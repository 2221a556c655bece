"""`gymgrade check` chooses the edition (flag, configuration or detection), says which and why, grades it."""

import json
import zipfile
from pathlib import Path

import pytest

from grader import cli
from grader.lab.editions import EDITIONS
from grader.report import Report

RL1 = EDITIONS["rl1"]
CLASSIC_COMPLETE = EDITIONS["classic"].reference


@pytest.mark.slow  # a grading through the sandbox
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
    assert f"--edition rl1 grades {', '.join(RL1.registry.ids)}, but {config}" in capsys.readouterr().err


def test_the_edition_flag_lists_every_edition(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        cli.build_parser().parse_args(["check", "x.py", "--edition", "rl9"])
    assert "choose from classic, gym026, volume2, rl1" in capsys.readouterr().err.replace("'", "")


def _class(root: Path, **sources: bytes) -> Path:
    for student, source in sources.items():
        (root / student).mkdir(parents=True)
        (root / student / "opengym.py").write_bytes(source)
    return root


@pytest.mark.slow  # a grading through the sandbox
def test_grade_without_an_edition_grades_the_one_the_files_show(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    inputs = _class(
        tmp_path / "inputs", alice=RL1.reference.read_bytes(), bob=RL1.template.read_bytes(), carol=b""
    )
    out = tmp_path / "out"
    argv = ["grade", str(inputs), "--out", str(out), "--only", "epsilon_decay", "--workers", "1"]
    assert cli.main(argv) == 0
    err = capsys.readouterr().err
    assert (
        "Edition: rl1 (Reinforcement Learning 1: Gymnasium): no --edition and no configuration; every file"
        in (err)
    )
    assert "  alice: rl1: it defines epsilon_decay(" in err and "  carol: no edition: " in err
    reports = {path.stem: Report.model_validate_json(path.read_text()) for path in out.glob("*.json")}
    assert {student: report.edition for student, report in reports.items()} == {
        "alice": "rl1", "bob": "rl1", "carol": "rl1"
    }  # fmt: skip
    statuses = {student: report.problems[0].status for student, report in reports.items()}
    assert statuses == {"alice": "passed", "bob": "missing", "carol": "missing"}


@pytest.mark.slow  # reads a class through the CLI
def test_grade_stops_before_grading_when_the_files_show_editions_of_different_problems(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Hostile: three classic files in a class of two rl1 files used to move the whole class to the first
    # edition (by majority); now nothing is graded until the instructor names the assignment's edition.
    classic = CLASSIC_COMPLETE.read_bytes()
    inputs = _class(
        tmp_path / "inputs",
        alice=RL1.reference.read_bytes(),
        bob=RL1.template.read_bytes(),
        mallory=classic,
        mallory2=classic,
        mallory3=classic,
    )
    out = tmp_path / "out"
    argv = ["grade", str(inputs), "--out", str(out), "--only", "epsilon_decay", "--workers", "1"]
    assert cli.main(argv) == cli.EXIT_ERROR
    err = capsys.readouterr().err
    assert (
        "gymgrade grade: the class's files were written for editions that ask different problems: classic "
        "(OpenGym AI (classic gym), 3): mallory, mallory2, mallory3; rl1 (Reinforcement Learning 1: "
        "Gymnasium, 2): alice, bob. What a student is graded on is the assignment's edition"
    ) in err
    assert "  mallory: classic: it imports gym" in err
    assert not out.exists() or not list(out.glob("*.json")), "nothing is graded"
    argv += ["--edition", "rl1"]
    assert cli.main(argv) == 0
    reports = {path.stem: Report.model_validate_json(path.read_text()) for path in out.glob("*.json")}
    assert {student: report.edition for student, report in reports.items()} == dict.fromkeys(reports, "rl1")
    note = reports["mallory"].edition_note
    assert note is not None and note.startswith(
        "This file looks written for edition 1 (classic, OpenGym AI (classic gym)): it imports gym"
    )
    assert note.endswith(
        "Your assignment is edition 4 (rl1, Reinforcement Learning 1: Gymnasium), so it was graded on that "
        "edition's problems; check the assignment's template."
    )
    assert reports["alice"].edition_note is None and reports["bob"].edition_note is None


@pytest.mark.slow  # a grading through the sandbox
def test_check_with_another_edition_tells_the_file_in_every_output(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    html = tmp_path / "report.html"
    argv = ["check", str(CLASSIC_COMPLETE), "--edition", "rl1", "--only", "epsilon_decay", "--workers", "1"]
    assert cli.main([*argv, "--html", str(html)]) == cli.EXIT_NOT_FULL
    told = "This file looks written for edition 1 (classic, OpenGym AI (classic gym))"
    assert told in capsys.readouterr().out
    assert told in html.read_text(encoding="utf-8")


@pytest.mark.slow  # a grading through the sandbox
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


RL2_SAMPLES = Path(__file__).resolve().parents[4] / "submissions" / "rl2"


def test_lab_and_an_edition_of_another_lab_is_a_usage_error_naming_both(
    capsys: pytest.CaptureFixture[str],
) -> None:
    argv = ["check", str(RL2_SAMPLES / "honest_v2024.py"), "--lab", "rl2", "--edition", "rl1"]
    assert cli.main(argv) == cli.EXIT_ERROR
    assert capsys.readouterr().err == (
        "gymgrade check: --edition rl1 is an edition of lab opengym (OpenGym AI / Reinforcement Learning 1), "
        "but --lab rl2 names lab rl2 (Policy Function Iteration / Reinforcement Learning 2): name one of "
        "rl2's editions (v2018, v2019, v2023, v2024, v2026), or drop --lab\n"
    )


@pytest.mark.parametrize("command", ["check", "grade", "gradescope-bundle"])
def test_an_unknown_lab_is_refused_listing_the_labs(command: str, capsys: pytest.CaptureFixture[str]) -> None:
    argv = {"check": ["check", "x.py"], "grade": ["grade", "x", "--out", "o"], "gradescope-bundle": [command]}
    with pytest.raises(SystemExit) as raised:
        cli.build_parser().parse_args([*argv[command], "--lab", "nonsense"])
    assert raised.value.code == 2
    assert (
        "argument --lab: invalid choice: nonsense (choose from opengym, rl2)"
        in capsys.readouterr().err.replace("'", "")
    )


def test_the_gradescope_bundle_of_a_lab_carries_its_current_editions_configuration(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from grader.cli.gradescope import bundle_config

    out = tmp_path / "autograder.zip"
    assert cli.main(["gradescope-bundle", "--lab", "rl2", "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "Lab: rl2 (Policy Function Iteration / Reinforcement Learning 2).\nEdition: v2026" in err
    assert bundle_config(out) == EDITIONS["v2026"].default_config.read_text(encoding="utf-8")


@pytest.mark.slow  # a grading through the sandbox
def test_a_second_lab_file_is_detected_and_its_report_names_the_lab(
    capsys: pytest.CaptureFixture[str],
) -> None:
    argv = ["check", str(RL2_SAMPLES / "honest_v2024.py"), "--only", "value_iteration", "--format", "json"]
    assert cli.main([*argv, "--workers", "1"]) == cli.EXIT_FULL_MARKS
    captured = capsys.readouterr()
    assert captured.err.startswith(
        "Lab: rl2 (Policy Function Iteration / Reinforcement Learning 2).\n"
        "Edition: v2024 (Reinforcement Learning 2: Markov Decision Process (2024)): detected from "
        "honest_v2024.py: it defines model_comparison(episodes)"
    )
    report = json.loads(captured.out)
    assert (report["lab"], report["edition"], report["problems"][0]["status"]) == ("rl2", "v2024", "passed")


@pytest.mark.slow  # reads a class through the CLI, then grades it
def test_a_second_lab_file_in_a_first_lab_class_stops_it_until_the_lab_is_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Hostile: a file defining the second lab's functions cannot move (or hide in) a first-lab class.
    inputs = _class(
        tmp_path / "inputs",
        alice=RL1.reference.read_bytes(),
        bob=RL1.template.read_bytes(),
        mallory=(RL2_SAMPLES / "honest_v2024.py").read_bytes(),
    )
    out = tmp_path / "out"
    argv = ["grade", str(inputs), "--out", str(out), "--only", "epsilon_decay", "--workers", "1"]
    assert cli.main(argv) == cli.EXIT_ERROR
    err = capsys.readouterr().err
    assert (
        "gymgrade grade: the class's files were written for different labs: opengym (OpenGym AI / "
        "Reinforcement Learning 1), 2: alice, bob; rl2 (Policy Function Iteration / Reinforcement Learning "
        "2), 1: mallory."
    ) in err
    assert not out.exists() or not list(out.glob("*.json")), "nothing is graded"
    assert cli.main([*argv, "--lab", "opengym"]) == 0
    assert "Lab: opengym (OpenGym AI / Reinforcement Learning 1).\nEdition: rl1" in capsys.readouterr().err
    reports = {path.stem: Report.model_validate_json(path.read_text()) for path in out.glob("*.json")}
    assert {student: (report.lab, report.edition) for student, report in reports.items()} == dict.fromkeys(
        reports, ("opengym", "rl1")
    )
    note = reports["mallory"].edition_note
    assert note is not None and note.startswith(
        "This file looks written for the lab rl2 (Policy Function Iteration / Reinforcement Learning 2)"
    )
