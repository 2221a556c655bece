"""Tests of grader/cli/__init__.py: exit codes, --json exactness, batch output, entry-point subcommands."""

from __future__ import annotations

import csv
import re
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from fake_problem import WITH_ECHO
from grading_support import CLASSIC_COMPLETE, FAST_OVERRIDES, SUBMISSIONS, write_config

from grader import cli
from grader.classroom import command
from grader.lab.problems import PROBLEMS
from grader.report import Report
from grader.sandbox.isolation import bubblewrap, cgroup, privileges, seccomp


@pytest.fixture(scope="module")
def fast_config(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_config(tmp_path_factory.mktemp("config") / "assignment.toml", FAST_OVERRIDES)


@pytest.mark.slow  # a grading through the sandbox
def test_check_json_prints_exactly_the_report_and_exits_0_at_full_marks(
    fast_config: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    output = tmp_path / "report.json"
    argv = [
        "check",
        str(CLASSIC_COMPLETE),
        "--only",
        "car",
        "--config",
        str(fast_config),
        "--seed",
        "4",
        "--json",
        "--output",
        str(output),
    ]
    assert cli.main(argv) == cli.EXIT_FULL_MARKS
    captured = capsys.readouterr()
    report = Report.model_validate_json(captured.out)
    assert captured.out == report.to_json() + "\n"
    assert output.read_text() == captured.out
    assert "[   PASS] Problem 4: MountainCar (1/1)" in captured.err, "progress goes to stderr with --json"


@pytest.mark.slow  # a grading through the sandbox
def test_check_explains_what_is_missing_and_exits_1(
    fast_config: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["check", str(SUBMISSIONS / "template.py"), "--only", "car", "--config", str(fast_config)]
    assert cli.main(argv) == cli.EXIT_NOT_FULL
    out = capsys.readouterr().out
    assert out.startswith("Checking template.py (practice seed 0)...\n")
    assert "[MISSING] Problem 4: MountainCar (0/1)" in out
    assert "car() raised NotImplementedError: not attempted yet." in out
    assert "Score: 0 / 1" in out
    assert (
        "Practice seed 0: your instructor grades on different, unseen starts (a held-out seed), so code "
        "that only does well from these starts will fail there." in out
    )


def test_check_of_a_symbolic_link_says_so_and_reads_nothing_of_its_target(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    secret = tmp_path / "secret.txt"
    secret.write_text("def epsilon_decay(n):\n    return 'hunter2'\n")  # an rl1 mark, if it were read
    (tmp_path / "opengym.py").symlink_to(secret)
    assert (
        cli.main(["check", str(tmp_path / "opengym.py"), "--only", "random_blackjack"]) == cli.EXIT_NOT_FULL
    )
    captured = capsys.readouterr()
    assert (
        f"opengym.py is a symbolic link (to {secret}): links are never followed, so it was not read. "
        "Submit the file itself, not a link to it." in captured.out
    )
    assert "Edition: classic" in captured.err and "epsilon_decay" not in captured.err, "detection read it"


QUICK_FIND_QVALUES = (
    "import numpy as np\n\n\ndef find_qvalues(env):\n    print('training a table')\n"
    "    return np.zeros((500, 6))\n"
)


@pytest.mark.slow  # a grading through the sandbox
def test_check_does_not_call_find_qvalues_when_no_verdict_needs_it(
    fast_config: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    submission = tmp_path / "opengym.py"
    submission.write_text(QUICK_FIND_QVALUES, encoding="utf-8")
    output = tmp_path / "report.json"
    argv = ["check", str(submission), "--only", "find_qvalues", "--config", str(fast_config)]
    assert cli.main([*argv, "--output", str(output)]) == cli.EXIT_FULL_MARKS
    out = capsys.readouterr().out
    assert "[SKIPPED] find_qvalues (provided by the lab) (0/0)" in out
    assert "  Not run: find_qvalues is worth 0 points and no other check needs its table" in out
    (result,) = Report.model_validate_json(output.read_text()).problems
    assert (result.status, result.output, result.measurements) == ("skipped", "", {"calls_made": 0})
    assert result.timings is not None and result.timings.student_seconds == 0.0


@pytest.mark.slow  # a grading through the sandbox
def test_check_calls_find_qvalues_when_the_config_says_always(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    config = write_config(tmp_path / "assignment.toml", {"find_qvalues": {"run": "always"}})
    submission = tmp_path / "opengym.py"
    submission.write_text(QUICK_FIND_QVALUES, encoding="utf-8")
    output = tmp_path / "report.json"
    argv = ["check", str(submission), "--only", "find_qvalues", "--config", str(config)]
    assert cli.main([*argv, "--output", str(output)]) == cli.EXIT_FULL_MARKS
    assert "[   PASS] find_qvalues (provided by the lab) (0/0)" in capsys.readouterr().out
    (result,) = Report.model_validate_json(output.read_text()).problems
    assert (result.status, result.output) == ("passed", "training a table\n")
    assert "greedy_mean_return" in result.measurements


def _forget_isolation_probes() -> None:
    # Each layer probes the machine once per process; a probe made under this PATH must neither be one
    # made before it nor outlive it (the next test in this process, whatever xdist sent it, grades for real).
    for layer in (bubblewrap, cgroup, privileges, seccomp):
        layer._probe_machine.cache_clear()


@pytest.fixture
def without_bubblewrap(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """A machine like a student's laptop: `bwrap` (and `setpriv`) cannot be found on PATH."""
    empty = tmp_path / "bin"
    empty.mkdir()
    monkeypatch.setenv("PATH", str(empty))
    _forget_isolation_probes()
    yield
    monkeypatch.undo()
    _forget_isolation_probes()


@pytest.mark.slow  # a grading through the sandbox
@pytest.mark.usefixtures("without_bubblewrap")
def test_check_runs_with_weaker_isolation_and_says_so(
    fast_config: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["check", str(CLASSIC_COMPLETE), "--only", "car", "--config", str(fast_config)]
    assert cli.main(argv) == cli.EXIT_FULL_MARKS
    out = capsys.readouterr().out
    assert "Sandbox: weaker isolation on this machine" in out
    assert "  - bubblewrap: bubblewrap (bwrap) is not installed" in out


@pytest.mark.slow
@pytest.mark.usefixtures("without_bubblewrap")
def test_grade_refuses_weaker_isolation_unless_allowed(
    fast_config: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["grade", str(CLASSIC_COMPLETE), "--out", str(tmp_path / "out"), "--only", "car"]
    assert cli.main([*argv, "--config", str(fast_config)]) == cli.EXIT_ERROR
    err = capsys.readouterr().err
    assert "full isolation is required to run untrusted submissions" in err
    assert "`gymgrade grade --allow-weak-isolation`" in err
    assert not (tmp_path / "out" / "grades.csv").exists()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["check", "no/such/file.py"], "no/such/file.py is not a file"),
        (
            ["check", str(CLASSIC_COMPLETE), "--config", "no/such/config.toml"],
            "no/such/config.toml not found",
        ),
        (["grade", "no/such/dir", "--out", "out"], "no/such/dir does not exist"),
    ],
    ids=["missing-file", "missing-config", "missing-batch-target"],
)
def test_usage_errors_exit_2_with_a_message(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert cli.main(argv) == cli.EXIT_ERROR
    assert message in capsys.readouterr().err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["check", str(CLASSIC_COMPLETE), "--only", "blackjak"], "unknown problem blackjak"),
        (
            ["check", str(CLASSIC_COMPLETE), "--workers", "0"],
            "expected a positive number of workers, found 0",
        ),
        (["grade", str(CLASSIC_COMPLETE)], "the following arguments are required: --out"),
        (["check", str(CLASSIC_COMPLETE), "--seed", "-1"], "expected a non-negative seed, found -1"),
        ([], "the following arguments are required: COMMAND"),
    ],
    ids=["unknown-problem", "zero-workers", "grade-without-out", "negative-seed", "no-command"],
)
def test_argument_errors_exit_2(argv: list[str], message: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        cli.main(argv)
    assert exit_info.value.code == cli.EXIT_ERROR
    assert message in capsys.readouterr().err


@pytest.mark.parametrize("registry", [PROBLEMS, WITH_ECHO], ids=["lab", "with-echo"])
def test_only_derives_its_help_ids_and_message_from_the_registry(
    registry: Any, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(cli, "all_problem_ids", lambda: registry.ids)
    parser = cli.build_parser()
    last = registry.ids[-1]
    parsed = parser.parse_args(["check", "opengym.py", "--only", f"{last},car"])
    assert parsed.only == ["car", last]
    with pytest.raises(SystemExit):
        parser.parse_args(["check", "opengym.py", "--help"])
    assert f"grade only these problems ({', '.join(registry.ids)}; each edition grades its own)" in " ".join(
        capsys.readouterr().out.split()
    )
    with pytest.raises(SystemExit):
        parser.parse_args(["check", "opengym.py", "--only", "blackjak"])
    expected = f"unknown problem blackjak; expected ids among {', '.join(registry.ids)}"
    assert expected in capsys.readouterr().err


@pytest.mark.slow  # a grading through the sandbox
def test_grade_writes_reports_and_grades_csv_with_plain_progress(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    inputs = tmp_path / "inputs"
    inputs.mkdir()
    (inputs / "alice.py").write_bytes(b"")
    (inputs / "bob.py").write_bytes(b"def car(:\n")
    out = tmp_path / "out"
    assert cli.main(["grade", str(inputs), "--out", str(out), "--only", "car,taxi"]) == 0
    err = capsys.readouterr().err
    assert "1/4 alice: car missing\n" in err and "4/4 bob: taxi error\n" in err
    assert "  alice: alice.py (the only .py/.ipynb file (nothing else))" in err
    rows = list(csv.DictReader((out / "grades.csv").open()))
    assert [(row["student"], row["car"], row["taxi"], row["total"]) for row in rows] == [
        ("alice", "0", "0", "0"),
        ("bob", "0", "0", "0"),
    ]
    assert sorted(path.name for path in out.iterdir()) == ["alice.json", "bob.json", "grades.csv"]
    announced = re.search(
        r"Grading seed (\d+) \(held out, drawn at random; regrade identically with --seed \1\)", err
    )
    assert announced is not None, err
    seed = int(announced[1])
    assert seed != 0, "without --seed the grading seed is held out, never the public practice seed"
    assert {row["seed"] for row in rows} == {str(seed)}
    assert {
        Report.model_validate_json((out / name).read_text()).seed for name in ["alice.json", "bob.json"]
    } == {seed}
    assert cli.main(["grade", str(inputs), "--out", str(out), "--only", "car,taxi"]) == 0
    assert (
        f"Grading seed {seed} (recorded in {out / 'grades.csv'}; pass --seed for another; regrade "
        f"identically with --seed {seed})" in capsys.readouterr().err
    ), "a re-run without --seed resumes with the batch's seed"


@pytest.mark.slow  # a grading through the sandbox
def test_grade_with_a_given_seed_records_it(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "alice.py").write_bytes(b"")
    out = tmp_path / "out"
    assert (
        cli.main(["grade", str(tmp_path / "alice.py"), "--out", str(out), "--only", "car", "--seed", "7"])
        == 0
    )
    assert "Grading seed 7 (given; regrade identically with --seed 7)" in capsys.readouterr().err
    assert [row["seed"] for row in csv.DictReader((out / "grades.csv").open())] == ["7"]
    assert Report.model_validate_json((out / "alice.json").read_text()).seed == 7


@dataclass
class FakeEntryPoint:
    """Stands in for an installed `gymgrade.commands` entry point."""

    name: str
    target: Any

    def load(self) -> Any:
        if isinstance(self.target, Exception):
            raise self.target
        return self.target


def _add_hello(subparsers: Any) -> None:
    hello = subparsers.add_parser("hello", help="say hello")
    hello.add_argument("--times", type=int, default=1)
    hello.set_defaults(handler=lambda args: 40 + args.times)


@pytest.mark.parametrize(
    ("entry_point", "argv", "code", "message"),
    [
        (FakeEntryPoint("hello", _add_hello), ["hello", "--times", "2"], 42, ""),
        (
            FakeEntryPoint("serve", ImportError("No module named 'uvicorn'")),
            ["serve"],
            cli.EXIT_ERROR,
            "gymgrade serve: the command could not be loaded (ImportError: No module named 'uvicorn')",
        ),
    ],
    ids=["registered", "broken"],
)
def test_entry_point_commands(
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    entry_point: FakeEntryPoint,
    argv: list[str],
    code: int,
    message: str,
) -> None:
    monkeypatch.setattr(
        cli, "entry_points", lambda group: [entry_point] if group == cli.COMMAND_GROUP else []
    )
    assert cli.main(argv) == code
    assert message in capsys.readouterr().err


ENDLESS = b"def random_blackjack(n):\n    while True:\n        pass\n"


def _children_of(parent: int) -> set[int]:
    """Live processes whose parent is ``parent`` (a grading's xdist workers are the batch's children)."""
    found = set()
    for entry in Path("/proc").iterdir():
        try:
            state, ppid = (entry / "stat").read_text().rsplit(")", 1)[1].split()[0:2]
        except (OSError, ValueError):
            continue
        if state != "Z" and int(ppid) == parent:
            found.add(int(entry.name))
    return found


def _alive(pids: set[int]) -> set[int]:
    """The processes among ``pids`` that still run (neither gone nor zombies)."""
    alive = set()
    for pid in pids:
        try:
            state = (Path("/proc") / str(pid) / "stat").read_text().rsplit(")", 1)[1].split()[0]
        except (OSError, IndexError):
            continue
        if state != "Z":
            alive.add(pid)
    return alive


HANG_SECONDS = 120
"""Bounds a hang only: waits poll for their event and end as soon as it happens."""


@pytest.mark.slow
def test_ctrl_c_keeps_finished_reports_and_a_rerun_resumes(tmp_path: Path, fast_config: Path) -> None:
    inputs, out = tmp_path / "inputs", tmp_path / "out"
    inputs.mkdir()
    (inputs / "empty.py").write_bytes(b"")
    (inputs / "endless.py").write_bytes(ENDLESS)
    argv = [sys.executable, "-m", "grader.cli", "grade", str(inputs), "--out", str(out)]
    argv += ["--only", "random_blackjack", "--config", str(fast_config), "--seed", "736251"]
    argv += ["--allow-weak-isolation"]
    batch = subprocess.Popen(argv, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + HANG_SECONDS
    # Interrupt while the endless file is being graded: the empty file's report is kept, and a worker runs
    # the endless file in a sandbox child of its own.
    while not (
        (out / "empty.json").exists() and any(_children_of(worker) for worker in _children_of(batch.pid))
    ):
        assert time.monotonic() < deadline, f"the batch did not start grading within {HANG_SECONDS} s"
        time.sleep(0.1)
    workers = _children_of(batch.pid)
    batch.send_signal(signal.SIGINT)
    _, err = batch.communicate(timeout=30)
    assert batch.returncode == cli.EXIT_INTERRUPTED, err
    assert (
        f"gymgrade grade: interrupted. 1 of 2 submissions are graded in {out} (their reports and grades.csv "
        "are kept). Run the same command again (same --out, --seed, --only and --config) to grade the "
        "other 1; the finished ones are skipped." in err
    )
    assert sorted(path.name for path in out.iterdir()) == ["empty.json", "grades.csv"]
    rows = list(csv.DictReader((out / "grades.csv").open()))
    assert [row["student"] for row in rows] == ["empty", "endless"]
    assert rows[0]["seed"] == "736251" and (rows[1]["seed"], rows[1]["note"]) == ("", "not graded yet")
    deadline = time.monotonic() + HANG_SECONDS  # killed processes take a moment to go; this bounds a hang
    while _alive(workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert workers and _alive(workers) == set(), "the interrupted grading left processes behind"

    (inputs / "endless.py").write_bytes(b"x = 1\n")
    rerun = subprocess.run(argv, capture_output=True, text=True, timeout=120)
    assert rerun.returncode == 0, rerun.stderr
    assert f"Resuming in {out}: 1 of 2 submissions are already graded there" in rerun.stderr
    assert "endless: random_blackjack missing" in rerun.stderr
    assert "empty:" not in rerun.stderr.split("grading 1.")[1]
    rows = list(csv.DictReader((out / "grades.csv").open()))
    assert [(row["student"], row["seed"]) for row in rows] == [("empty", "736251"), ("endless", "736251")]


def test_a_broken_executor_entry_point_is_refused_with_a_remedy(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    broken = FakeEntryPoint("cluster", ImportError("No module named 'celery'"))
    monkeypatch.setattr(
        command, "entry_points", lambda group: [broken] if group == command.EXECUTOR_GROUP else []
    )
    (tmp_path / "alice.py").write_bytes(b"")
    assert cli.main(["grade", str(tmp_path / "alice.py"), "--out", str(tmp_path / "out")]) == cli.EXIT_ERROR
    assert (
        "gymgrade grade: the batch executor 'cluster' could not be loaded (ImportError: No module named "
        "'celery'); reinstall the package providing it (pip install -e '.[distributed]')"
    ) in capsys.readouterr().err


def test_the_class_summary_shows_each_name_a_student_chose_as_one_inert_line(tmp_path: Path) -> None:
    """Hostile: folder and file names with escape sequences, BEL, a C1 control, a right-to-left override and
    a newline that would forge a `refused alice` line are printed inert, one line per student."""
    import zipfile

    from grader.classroom import discover

    klass = tmp_path / "class"
    names = ["\x1b]0;owned\x07\x1b[2Jmallory", "\x9b31mtrudy", "\u202eecila", "eve\n  refused alice: forged"]
    for name in names:
        (klass / name).mkdir(parents=True)
        (klass / name / "opengym.py").write_text("def blackjack(n):\n    return 0\n")
    with zipfile.ZipFile(klass / "eve\n  refused alice: forged" / "more.zip", "w") as bundle:
        bundle.writestr("../\x1b[2J.py", "x = 1\n")
    printed = command.class_summary(discover(klass, scratch=tmp_path / "scratch"))
    lines = printed.split("\n")
    assert len(lines) == 1 + len(names) + 1, printed
    assert not any(line.startswith("  refused alice") for line in lines)
    assert [character for character in printed if character in "\x1b\x07\x9b\u202e\r"] == []
    assert "  \ufffd]0;owned\ufffd\ufffd[2Jmallory: " in printed
    assert "  refused eve refused alice: forged/more.zip/../\ufffd[2J.py: a name climbing out" in printed
