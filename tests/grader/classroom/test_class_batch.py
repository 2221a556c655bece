"""A class batch keyed by identity: report files, resume keys and gradebook rows are the students'; a
re-run with more students adds rows and changes none; and one real `gymgrade grade` of a Canvas zip."""

from __future__ import annotations

import csv
import hashlib
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from grading_support import FAST_OVERRIDES, write_config

import grader
from grader import cli
from grader.classroom import GradedFileRule, command, discover
from grader.classroom.output import ClassGradebook
from grader.grading.batch import grade_many, identity_stem
from grader.grading.outcomes import GradingListener
from grader.grading.plan import GradingPlan
from grader.report import ProblemResult, Report

from .canvas_import import canvas_import
from .downloads import BUILDERS, DUE

RULE = GradedFileRule(functions=("random_blackjack", "blackjack", "cartpole", "car", "taxi", "find_qvalues"))
ONLY = ("random_blackjack",)


@dataclass
class FakeExecutor:
    """Grades each file into a report of its bytes (1 for the lab's solution, file or notebook, else 0)."""

    asked: list[list[Path]] = field(default_factory=list)

    def grade(
        self,
        paths: Sequence[Path],
        plan: GradingPlan,
        *,
        seed: int,
        listener: GradingListener,
        file_names: Mapping[Path, str] | None = None,
    ) -> None:
        self.asked.append(list(paths))
        for path in paths:
            data = path.read_bytes()
            score = 1.0 if b"def find_qvalues(env, alpha=.1" in data else 0.0
            results = [
                ProblemResult(
                    id=p,
                    title=p,
                    status="passed" if score else "failed",
                    score=score,
                    max_score=1.0,
                    feedback="",
                )
                for p in plan.problems
            ]
            listener.report(
                path,
                Report(
                    submission=(file_names or {}).get(path) or path.name,
                    sha256=hashlib.sha256(data).hexdigest(),
                    seed=seed,
                    gymnasium_version="1.4.0",
                    grader_version=grader.__version__,
                    config_sha256=plan.config_sha256,
                    score=score * len(results),
                    max_score=float(len(results)),
                    problems=results,
                ),
            )


def _batch(path: Path, out: Path, executor: FakeExecutor, **options: object) -> list[dict[str, str]]:
    download = discover(path, rule=RULE, scratch=out.parent / f"scratch-{len(executor.asked)}", due=DUE)
    identities = {s.graded_file.path: s.identity for s in download.submissions if s.graded_file}
    plan = GradingPlan.load(None, ONLY)
    gradebook = ClassGradebook(download, identities, plan.problems, **options)  # type: ignore[arg-type]
    grade_many(
        list(identities), out, seed=5, only=ONLY, executor=executor, names=identities, gradebook=gradebook
    )
    return list(csv.DictReader((out / "grades.csv").open(encoding="utf-8", newline="")))


@pytest.mark.parametrize("layout", list(BUILDERS), ids=list(BUILDERS))
def test_reports_are_named_by_identity_and_a_rerun_grades_nothing(layout: str, tmp_path: Path) -> None:
    expected = BUILDERS[layout](tmp_path / "download", 3)
    executor = FakeExecutor()
    first = _batch(expected.path, tmp_path / "out", executor)
    graded = {identity for identity, file in expected.graded.items() if file}
    reports = sorted(path.name for path in (tmp_path / "out").glob("*.json"))
    assert reports == sorted(f"{identity_stem(identity)}.json" for identity in graded)
    second = _batch(expected.path, tmp_path / "out", executor)
    assert len(executor.asked) == 1, "the re-run reused every report (keyed by identity)"
    assert first == second


def test_more_students_add_rows_and_change_none(tmp_path: Path) -> None:
    small = BUILDERS["gradescope"](tmp_path / "small", 2)
    large = BUILDERS["gradescope"](tmp_path / "large", 5)
    executor = FakeExecutor()
    before = _batch(small.path, tmp_path / "out", executor)
    after = _batch(large.path, tmp_path / "out", executor)
    assert [row for row in after if row in before] == before, "every earlier row is unchanged"
    assert len(after) == len(before) + 3
    assert [len(paths) for paths in executor.asked] == [5, 3], "only the new students were graded"


def test_an_identity_that_is_not_a_safe_file_name_is_encoded() -> None:
    assert identity_stem("ada/../../etc") == "ada%2F..%2F..%2Fetc"
    assert identity_stem(".hidden") == "%2Ehidden"
    assert identity_stem("000123") == "000123"
    assert identity_stem("Zoë Ng (7)") == "Zo%C3%AB Ng (7)"


@pytest.fixture(scope="module")
def fast_config(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_config(tmp_path_factory.mktemp("config") / "fast.toml", FAST_OVERRIDES)


@pytest.mark.slow  # a grading through the sandbox
def test_gymgrade_grade_a_canvas_zip_into_every_gradebook(
    tmp_path: Path, fast_config: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The real thing, once: a Canvas download as it comes, graded on random_blackjack."""
    expected = BUILDERS["canvas"](tmp_path / "download", 1)
    out = tmp_path / "out"
    argv = ["grade", str(expected.path), "--out", str(out), "--only", "random_blackjack", "--seed", "11"]
    argv += ["--config", str(fast_config), "--allow-weak-isolation", "--due", DUE.isoformat()]
    argv += ["--gradebook", "canvas", "--gradebook", "gradescope", "--gradebook", "github-classroom"]
    argv += ["--assignment-title", "OpenGym lab", "--assignment-id", "777"]
    assert cli.main(argv) == 0
    err = capsys.readouterr().err
    assert "Found 7 submissions (Canvas Download Submissions):" in err
    assert (
        "  lovelaceada (2001): lovelaceada_2001_6007_opengym-1.py (named opengym.py, the lab's file name; 1 earlier upload of the same name left out)"  # noqa: E501
        in err
    )
    assert "  obrienbob (2002) [late]: obrienbob_LATE_2002_6002_opengym.py" in err
    assert "  refused malloryeve_2006_6009_opengym.py: a symbolic link stored in the zip" in err
    assert (
        "  not attributed grades_from_last_year.csv: not named {name}_{user id}_{attachment id}_{file}" in err
    )
    assert "2001: random_blackjack passed" in err
    rows = list(csv.DictReader((out / "grades.csv").open(encoding="utf-8")))
    totals = {row["student"]: row["total"] for row in rows}
    assert totals == dict.fromkeys(["1000", "2001", "2002", "2003", "2004", "2005"], "1") | {"2006": ""}
    graded = {user for user, total in totals.items() if total}
    changes = canvas_import((out / "canvas.csv").read_text(encoding="utf-8"), set(totals), {"777": 1.0})
    assert changes == {(user, "777"): 1.0 for user in graded}
    assert sorted(path.name for path in out.iterdir()) == sorted(
        [
            "grades.csv",
            "canvas.csv",
            "gradescope.csv",
            "github-classroom.csv",
            *(f"{user}.json" for user in graded),
        ]
    )


@dataclass
class InterruptingExecutor(FakeExecutor):
    """Stops (as Ctrl-C would) after grading ``after`` files."""

    after: int = 2

    def grade(self, paths: Sequence[Path], plan: GradingPlan, **options: object) -> None:  # type: ignore[override]
        super().grade(paths[: self.after], plan, **options)  # type: ignore[arg-type]
        raise KeyboardInterrupt


def test_an_interrupted_batch_leaves_gradebooks_with_every_finished_report(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from grader.errors import BatchInterrupted
    from grader.grading import batch

    monkeypatch.setattr(batch, "GRADEBOOK_INTERVAL", 3600.0)  # only the first report rewrites at once
    expected = BUILDERS["plain"](tmp_path / "download", 3)
    with pytest.raises(BatchInterrupted):
        _batch(expected.path, tmp_path / "out", InterruptingExecutor(after=3))
    rows = list(csv.DictReader((tmp_path / "out" / "grades.csv").open(encoding="utf-8")))
    assert sum(1 for row in rows if row["total"]) == 3
    assert (
        sum(1 for row in rows if row["note"] == "not graded yet") == len(rows) - 3 - 1
    )  # eve: nothing graded


@pytest.mark.slow  # a grading through the sandbox
@pytest.mark.parametrize("layout", list(BUILDERS), ids=list(BUILDERS))
def test_gymgrade_grade_each_layout_into_every_gradebook(
    layout: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The command's whole path but grading (an instant executor stands in for the sandbox)."""
    monkeypatch.setattr(command, "find_executor", lambda policy: FakeExecutor())
    expected = BUILDERS[layout](tmp_path / "download", 3)
    out = tmp_path / "out"
    argv = ["grade", str(expected.path), "--out", str(out), "--only", "random_blackjack", "--seed", "3"]
    argv += ["--due", DUE.isoformat(), "--assignment-id", "9"]
    argv += ["--gradebook", "canvas", "--gradebook", "gradescope", "--gradebook", "github-classroom"]
    argv += ["--html", str(tmp_path / "class.html")]
    roster = expected.path.parent / "roster.csv"
    if roster.exists():
        argv += ["--roster", str(roster)]
    assert cli.main(argv) == 0
    err = capsys.readouterr().err
    assert f"Grading on {FakeExecutor()}." in err
    if layout == "canvas":
        assert "canvas.csv leaves out" not in err
    else:
        assert "without a Canvas user id" in err and "pass --roster with a Canvas gradebook export" in err
    rows = list(csv.DictReader((out / "grades.csv").open(encoding="utf-8")))
    members = {identity: expected.groups.get(identity, (identity,)) for identity in expected.graded}
    students = sorted(member for group in members.values() for member in group)
    on_roster_only = ["never-submitted"] if roster.exists() else []
    assert [row["student"].removeprefix("'") for row in rows] == sorted(students + on_roster_only)
    graded = {m for identity, file in expected.graded.items() if file for m in members[identity]}
    assert {row["student"].removeprefix("'") for row in rows if row["total"] == "1"} == graded
    assert {row["student"] for row in rows if row["late"] == "late"} == {
        m for identity in expected.late for m in members[identity]
    }
    for name in ("gradescope.csv", "github-classroom.csv"):
        other = list(csv.reader((out / name).open(encoding="utf-8")))
        assert len(other) == len(rows) + 1, f"{name}: a row per student"
    summary = json.loads((tmp_path / "class.json").read_text(encoding="utf-8"))
    assert sorted(entry["identity"] for entry in summary["entries"]) == sorted(students + on_roster_only)
    assert summary["missing"] == on_roster_only
    assert sorted(summary["late"]) == sorted(m for identity in expected.late for m in members[identity])
    for entry in summary["entries"]:
        if entry["identity"] in graded:
            assert entry["status"] == "graded" and entry["score"] == 1.0
            assert (tmp_path / entry["report_href"]).resolve().parent == out.resolve()
    canvas = list(csv.reader((out / "canvas.csv").open(encoding="utf-8")))
    assert canvas[1][0] == "    Points Possible"
    if layout == "canvas":
        assert {row[1] for row in canvas[2:]} == set(students)


def test_hostile_folder_names_stay_data(tmp_path: Path) -> None:
    folder = tmp_path / "class"
    names = ["line\nbreak", '=HYPERLINK("x")', "@SUM(A1)", "-2+3", ".hidden"]
    for name in names:
        target = folder / name
        target.mkdir(parents=True)
        (target / "opengym.py").write_text("def find_qvalues(env, alpha=.1):\n    return 0\n")
    rows = _batch(folder, tmp_path / "out", FakeExecutor())
    students = [row["student"] for row in rows]
    expected = ["'-2+3", '\'=HYPERLINK("x")', "'@SUM(A1)", "line\nbreak"]  # .hidden is skipped like .git
    assert students == sorted(expected, key=lambda student: student.lstrip("'"))
    reports = sorted(path.name for path in (tmp_path / "out").glob("*.json"))
    assert "line%0Abreak.json" in reports and all("/" not in name for name in reports)


def test_a_class_zip_with_a_161_byte_name_and_escaping_entries_grades_and_resumes(tmp_path: Path) -> None:
    """Hostile: a student folder named by a digit and 80 `é` (161 bytes, 481 once percent-encoded) and
    entries named ``../x``, ``/tmp/x`` and ``C:/x``: every honest student is graded, the long name's report
    is written under a bounded name, no refused entry becomes a row, and a re-run grades nothing."""
    import zipfile

    long_name = "1" + "é" * 80
    archive = tmp_path / "class.zip"
    with zipfile.ZipFile(archive, "w") as bundle:
        for name in (long_name, "alice", "bob"):
            bundle.writestr(f"{name}/opengym.py", "def blackjack(n):\n    return 0\n")
        for escaping in ("../x.py", "/tmp/x.py", "C:/x.py"):
            bundle.writestr(escaping, "x = 1\n")
    executor = FakeExecutor()
    rows = _batch(archive, tmp_path / "out", executor)
    assert sorted(row["student"] for row in rows) == sorted([long_name, "alice", "bob"])
    assert all(row["note"] == "" for row in rows), rows
    stems = sorted(path.stem for path in (tmp_path / "out").glob("*.json"))
    assert stems == sorted(["alice", "bob", identity_stem(long_name)])
    assert _batch(archive, tmp_path / "out", executor) == rows
    assert len(executor.asked) == 1, "the re-run found every report, the long name's included"


def test_a_class_zip_is_extracted_once_whatever_edition_it_is_graded_as(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # Hostile shape (scaled down): a zip of many 1 MiB entries of zeros used to be extracted twice when the
    # class's edition asked other functions than the first edition's, doubling what it wrote to /tmp.
    import zipfile

    from grader.classroom import discovery
    from grader.lab.editions import EDITIONS

    monkeypatch.setattr(command, "find_executor", lambda policy: FakeExecutor())
    reads: list[Path] = []
    real_read_tree = discovery.read_tree

    def counting(root: Path, *args: object) -> object:
        reads.append(root)
        return real_read_tree(root, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(discovery, "read_tree", counting)
    archive = tmp_path / "class.zip"
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_DEFLATED) as bundle:
        for student in ("alice", "bob"):
            bundle.writestr(f"{student}/opengym.py", EDITIONS["rl1"].reference.read_bytes())
            for number in range(3):
                bundle.writestr(f"{student}/zeros{number}.bin", b"\0" * 2**20)
    argv = ["grade", str(archive), "--out", str(tmp_path / "out"), "--only", "epsilon_decay", "--seed", "3"]
    assert cli.main(argv) == 0
    assert "Edition: rl1" in capsys.readouterr().err
    assert reads == [archive], "read once: grouped again by the rl1 functions without extracting again"
