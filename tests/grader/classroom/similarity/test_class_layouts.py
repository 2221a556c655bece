"""`gymgrade similarity` reads a class as `gymgrade grade` does (grader/classroom/): a Canvas zip and a
Gradescope export find the planted copied pair under the students' identities, refused and unattributed
files are listed with their reason, zips are read in a scratch folder that is removed; and
`gymgrade grade --similarity` writes the check beside the grades, with the batch's reports as evidence."""

from __future__ import annotations

import csv
import hashlib
import json
import os
import stat
import tempfile
import zipfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import pytest
from grading_support import FAST_OVERRIDES, write_config

import grader
from classroom.downloads import BUILDERS
from grader import cli
from grader.classroom import command
from grader.classroom.similarity.run import run_similarity
from grader.classroom.similarity.sources import submissions_from
from grader.grading.batch import identity_stem
from grader.grading.outcomes import GradingListener
from grader.grading.plan import GradingPlan
from grader.report import ProblemResult, Report

pytestmark = pytest.mark.slow  # grades and compares whole classes

CLASS = Path(__file__).resolve().parents[4] / "submissions" / "similarity" / "class"
ORIGINAL = (CLASS / "h01_loops.py").read_bytes()
COPY = (CLASS / "c_renamed_from_h01.py").read_bytes()
HONEST = [(CLASS / name).read_bytes() for name in ("h02_helpers.py", "h03_class.py", "h07_terse.py")]
TEST_FILE = b"from opengym import random_blackjack\n\ndef test_rate():\n    assert random_blackjack(9) >= 0\n"


def _rows(out: Path) -> list[dict[str, str]]:
    with (out / "similarity.csv").open(encoding="utf-8", newline="") as stream:
        return list(csv.DictReader(stream))


def _unreadable(out: Path) -> dict[str, tuple[str, str]]:
    report = json.loads((out / "similarity.json").read_text(encoding="utf-8"))
    return {entry["file"]: (entry["identity"], entry["reason"]) for entry in report["unreadable"]}


def canvas_zip(root: Path) -> Path:
    """A Canvas "Download Submissions" zip: user 1001 wrote h01, user 1009 copied it (renamed), a re-upload,
    a student's own test file, a symlink entry, a ``../`` entry and a stray CSV."""
    path = root / "submissions.zip"
    root.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as bundle:
        bundle.writestr("adaada_1001_5001_opengym.py", ORIGINAL)
        bundle.writestr("adaada_1001_5002_test_opengym.py", TEST_FILE)
        for number, honest in enumerate(HONEST, start=2):
            bundle.writestr(f"student{number}_100{number}_500{number + 2}_opengym.py", honest)
        bundle.writestr("copycat_1009_5010_opengym.py", b"def random_blackjack(n):\n    return 0\n")
        bundle.writestr("copycat_1009_5011_opengym-1.py", COPY)
        link = zipfile.ZipInfo("malloryeve_2006_6009_opengym.py")
        link.external_attr = (stat.S_IFLNK | 0o777) << 16
        bundle.writestr(link, "/etc/passwd")
        bundle.writestr("../../escaped_2007_6010_opengym.py", ORIGINAL)
        bundle.writestr("grades_from_last_year.csv", b"a,b\n")
    return path


def gradescope_export(root: Path) -> Path:
    """``assignment_{id}_export/``: SIDs with leading zeros, the copy in a pair's group submission, one
    student's file in ``src/`` beside a helper, a symlinked file and a folder the metadata does not name."""
    base = root / "assignment_4242_export"
    records: list[str] = []

    def submit(folder: str, submitters: list[tuple[str, str]], files: dict[str, bytes]) -> None:
        for name, data in files.items():
            (base / folder / name).parent.mkdir(parents=True, exist_ok=True)
            (base / folder / name).write_bytes(data)
        lines = [f"{folder}:", "  :submitters:"]
        for name, sid in submitters:
            lines += [f"  - :name: {json.dumps(name)}", f"    :sid: '{sid}'", f"    :email: {sid}@uni.edu"]
        lines += ["  :created_at: 2026-02-28 10:00:00.000000000 +00:00", "  :score: 0.0", "  :history: []"]
        records.append("\n".join(lines))

    submit("submission_1", [("Ada Lovelace", "000101")], {"opengym.py": ORIGINAL})
    for number, honest in enumerate(HONEST, start=2):
        submit(f"submission_{number}", [(f"Student {number}", f"00010{number}")], {"opengym.py": honest})
    submit(
        "submission_7",
        [("Cleo Pat", "000107"), ("Dee Ray", "000108")],
        {"src/agent.py": COPY, "src/utils.py": b"def clamp(x, lo, hi):\n    return max(lo, min(hi, x))\n"},
    )
    (base / "submission_8").mkdir(parents=True)
    os.symlink("../submission_1/opengym.py", base / "submission_8" / "opengym.py")
    submit("submission_8", [("Eve Mallory", "000109")], {})
    (base / "submission_9999").mkdir()
    (base / "submission_9999" / "opengym.py").write_bytes(ORIGINAL)
    (base / "submission_metadata.yml").write_text("\n".join(records) + "\n", encoding="utf-8")
    return root


def test_a_canvas_zip_finds_the_copied_pair_under_canvas_user_ids(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "out"
    scratch = tmp_path / "tmp"  # this test's own temporary directory: other tests' scratch comes and goes
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    zip_path = canvas_zip(tmp_path / "download")
    assert cli.main(["similarity", str(zip_path), "--out", str(out), "--no-cache"]) == 0
    assert list(scratch.iterdir()) == [], "scratch removed"
    rows = _rows(out)
    assert [(row["a"], row["b"]) for row in rows] == [("1001", "1009")]
    left_out = _unreadable(out)
    assert left_out["malloryeve_2006_6009_opengym.py"][0] == "2006"
    assert "symbolic link" in left_out["malloryeve_2006_6009_opengym.py"][1]
    assert left_out["../../escaped_2007_6010_opengym.py"][0] == "(refused)"
    assert left_out["grades_from_last_year.csv"][0] == "(not attributed)"
    assert left_out["grades_from_last_year.csv"][1].startswith("not attributed to a student: not named")
    printed = capsys.readouterr().out
    assert "left out grades_from_last_year.csv ((not attributed)): not attributed to a student" in printed
    assert "Compared 5 students with each other: 1 pairs flagged" in printed


def test_a_gradescope_export_finds_the_copy_in_a_group_submission(tmp_path: Path) -> None:
    out = tmp_path / "out"
    root = gradescope_export(tmp_path / "download")
    assert cli.main(["similarity", str(root), "--out", str(out), "--no-cache"]) == 0
    assert [(row["a"], row["b"]) for row in _rows(out)] == [("000101", "000107+000108")]
    left_out = _unreadable(out)
    assert left_out["assignment_4242_export/submission_8/opengym.py"][0] == "000109"
    assert left_out["assignment_4242_export/submission_9999/opengym.py"][0] == "(not attributed)"
    compared = json.loads((out / "similarity.json").read_text(encoding="utf-8"))["students"]
    assert compared == ["000101", "000102", "000103", "000104", "000107+000108"]


def test_layout_is_passed_through_and_a_wrong_one_is_an_error_that_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    zip_path = canvas_zip(tmp_path / "download")
    argv = ["similarity", str(zip_path), "--out", str(tmp_path / "out"), "--no-cache", "--layout"]
    assert cli.main([*argv, "canvas"]) == 0
    assert [(row["a"], row["b"]) for row in _rows(tmp_path / "out")] == [("1001", "1009")]
    assert cli.main([*argv, "gradescope"]) != 0
    assert "does not look like a Gradescope" in capsys.readouterr().err


@dataclass
class PlannedExecutor:
    """Stands in for the sandbox: each file fails random_blackjack with the rate planned for its bytes."""

    rates: dict[bytes, float]

    def grade(
        self,
        paths: Sequence[Path],
        plan: GradingPlan,
        *,
        seed: int,
        listener: GradingListener,
        file_names: Mapping[Path, str] | None = None,
    ) -> None:
        for path in paths:
            data = path.read_bytes()
            results = [
                ProblemResult(
                    id=problem,
                    title=problem,
                    status="failed",
                    score=0.0,
                    max_score=1.0,
                    feedback="",
                    measurements={"rate": self.rates[data]},
                )
                for problem in plan.problems
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
                    score=0.0,
                    max_score=float(len(results)),
                    problems=results,
                ),
            )


def test_grade_similarity_reads_the_batch_reports_by_their_encoded_names(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Identities that are not safe file names: the reports are found where the batch wrote them."""
    folder = tmp_path / "class"
    for name, data in (("zoë ng", ORIGINAL), ("ben", COPY), ("cy", HONEST[0])):
        (folder / name).mkdir(parents=True)
        (folder / name / "opengym.py").write_bytes(data)
    rates = {ORIGINAL: 0.0913, COPY: 0.0913, HONEST[0]: 0.377}
    monkeypatch.setattr(command, "find_executor", lambda policy: PlannedExecutor(rates))
    out = tmp_path / "out"
    argv = ["grade", str(folder), "--out", str(out), "--only", "random_blackjack", "--seed", "3"]
    assert cli.main([*argv, "--similarity", "--allow-weak-isolation"]) == 0
    assert (out / f"{identity_stem('zoë ng')}.json").is_file()
    assert identity_stem("zoë ng") != "zoë ng", "the test needs an identity whose report name is encoded"
    (row,) = _rows(out)
    assert (row["a"], row["b"]) == ("ben", "zoë ng")
    assert "the same wrong result on random_blackjack from the same seed (3)" in row["evidence"]


@pytest.fixture(scope="module")
def fast_config(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_config(tmp_path_factory.mktemp("config") / "fast.toml", FAST_OVERRIDES)


def test_gymgrade_grade_with_similarity_end_to_end_changes_no_grade(
    tmp_path: Path, fast_config: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The real sandbox, once: three students on random_blackjack, graded, then again with --similarity
    (every report reused): grades.csv and the reports keep their bytes, the similarity files are added."""
    folder = tmp_path / "class"
    for name, data in (("ana", ORIGINAL), ("ben", COPY), ("cy", HONEST[0])):
        (folder / name).mkdir(parents=True)
        (folder / name / "opengym.py").write_bytes(data)
    out = tmp_path / "out"
    argv = ["grade", str(folder), "--out", str(out), "--only", "random_blackjack", "--seed", "11"]
    argv += ["--config", str(fast_config), "--allow-weak-isolation"]
    assert cli.main(argv) == 0
    graded = {path.name: path.read_bytes() for path in out.iterdir()}
    assert sorted(graded) == ["ana.json", "ben.json", "cy.json", "grades.csv"]
    capsys.readouterr()
    assert cli.main([*argv, "--similarity"]) == 0
    err = capsys.readouterr().err
    assert "Compared 3 students with each other: 1 pairs flagged" in err
    assert {name: (out / name).read_bytes() for name in graded} == graded
    assert sorted(path.name for path in out.iterdir()) == sorted(
        [*graded, "similarity.csv", "similarity.html", "similarity.json"]
    )
    assert [(row["a"], row["b"]) for row in _rows(out)] == [("ana", "ben")]


def test_a_student_whose_report_would_be_similarity_json_stops_before_grading(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "class"
    (folder / "similarity").mkdir(parents=True)
    (folder / "similarity" / "opengym.py").write_bytes(ORIGINAL)
    argv = ["grade", str(folder), "--out", str(tmp_path / "out"), "--similarity", "--allow-weak-isolation"]
    assert cli.main(argv) != 0
    assert "student 'similarity''s report has that name" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_a_class_page_named_like_the_similarity_page_stops_before_grading(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "class"
    (folder / "ana").mkdir(parents=True)
    (folder / "ana" / "opengym.py").write_bytes(ORIGINAL)
    out = tmp_path / "out"
    argv = ["grade", str(folder), "--out", str(out), "--similarity", "--html", str(out / "similarity.html")]
    assert cli.main(argv) != 0
    assert "is one of them; name the class page e.g. class.html" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize("layout", sorted(BUILDERS))
def test_every_layout_grade_reads_is_compared_one_document_per_graded_student(
    layout: str, tmp_path: Path
) -> None:
    """The classroom tests' downloads of each layout: every student grading would grade is compared, under
    the same identity; nothing stops the run."""
    expected = BUILDERS[layout](tmp_path / "download", 2)
    with tempfile.TemporaryDirectory() as scratch:
        sources = submissions_from(expected.path, scratch=Path(scratch))
        report = run_similarity(sources, workers=1).report
    graded = sorted(identity for identity, file in expected.graded.items() if file is not None)
    assert sources.layout == expected.layout
    assert set(graded) <= set(report.students)
    for where in expected.refused + expected.unattributed:
        assert any(entry.file == where for entry in report.unreadable), (where, report.unreadable)
