"""A class read from a zip is graded from numbered copies (``6.py``: no name a student chose reaches the file
system), but what a person reads names each file as the download does: the feedback of a broken file, the
report's ``submission``, the gradebook's note and the similarity check. A hostile name is shown neutralised
and bounded and is never a path; a folder's files keep their own names as before."""

from __future__ import annotations

import csv
import io
import json
import re
import zipfile
from pathlib import Path

import pytest
from grading_support import FAST_OVERRIDES, write_config

from grader import cli
from grader.classroom import GradedFileRule, command, discover
from grader.classroom.output import ClassGradebook
from grader.classroom.similarity.run import run_similarity
from grader.classroom.similarity.sources import sources_of
from grader.grading.batch import grade_many
from grader.grading.plan import GradingPlan
from grader.render.neutral import MAX_FILE_NAME_CHARS, file_name

from .downloads import DUE, SOLUTION

RULE = GradedFileRule(functions=("random_blackjack", "blackjack", "cartpole", "car", "taxi", "find_qvalues"))
ONLY = ("random_blackjack",)
BROKEN = b"def random_blackjack(n):\n    return (\n"
NOT_JSON = b"{ this is not a notebook"
BROKEN_ENTRY = "smithjohn_3001_7001_policy_iteration-1.py"
NOTEBOOK_ENTRY = "doejane_3002_7002_opengym.ipynb"
HONEST_ENTRY = "leeann_3003_7003_opengym.py"
HOSTILE_FILE = "=cmd|' -C calc'!A0\x1b]0;owned\x07\u202egpj" + "x" * 400 + ".py"
HOSTILE_ZIP = "mallory_3004_7004_lab.zip"
"""A student's own zip in the download, holding a file named ``HOSTILE_FILE``."""


def _canvas_zip(path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as bundle:
        bundle.writestr(BROKEN_ENTRY, BROKEN)
        bundle.writestr(NOTEBOOK_ENTRY, NOT_JSON)
        bundle.writestr(HONEST_ENTRY, SOLUTION)
        inner = io.BytesIO()
        with zipfile.ZipFile(inner, "w") as own:
            own.writestr(HOSTILE_FILE, BROKEN)
        bundle.writestr(HOSTILE_ZIP, inner.getvalue())
    return path


NUMBERED: set[str] = set()
"""The numbered copies' names a zip was read into (filled as the tests read it)."""


def _grade_refused(download_path: Path, out: Path) -> dict[str, dict[str, object]]:
    """Grade the refused files (none reaches the sandbox) into ``out``; their reports by identity."""
    download = discover(download_path, rule=RULE, scratch=out.parent / "scratch", due=DUE)
    graded = [s for s in download.submissions if s.graded_file is not None]
    NUMBERED.update(s.graded_file.path.name for s in graded if s.graded_file)
    identities = {s.graded_file.path: s.identity for s in graded if s.graded_file}
    refused = [path for path, identity in identities.items() if identity != "3003"]
    plan = GradingPlan.load(None, ONLY)
    gradebook = ClassGradebook(download, identities, plan.problems)
    grade_many(
        refused,
        out,
        seed=5,
        only=ONLY,
        names=identities,
        gradebook=gradebook,
        file_names=command.file_names_of(graded),
    )
    return {
        identities[path]: json.loads((out / f"{identities[path]}.json").read_text("utf-8"))
        for path in refused
    }


def test_a_canvas_zips_files_are_named_as_the_download_names_them(tmp_path: Path) -> None:
    reports = _grade_refused(_canvas_zip(tmp_path / "download" / "submissions.zip"), tmp_path / "out")
    broken = reports["3001"]
    assert broken["submission"] == BROKEN_ENTRY
    assert broken["submission_error"] == (
        f"{BROKEN_ENTRY} is not valid Python: '(' was never closed (line 2, column 12). "
        f"Fix the syntax (`python -m py_compile {BROKEN_ENTRY}` shows it) and submit again."
    )
    notebook = reports["3002"]
    assert notebook["submission"] == NOTEBOOK_ENTRY
    assert str(notebook["submission_error"]).startswith(f"{NOTEBOOK_ENTRY} ")
    rows = {
        row["student"]: row
        for row in csv.DictReader((tmp_path / "out" / "grades.csv").open(encoding="utf-8"))
    }
    assert BROKEN_ENTRY in rows["3001"]["note"]
    assert {"0.py", "1.ipynb"} <= NUMBERED
    for report in reports.values():  # the numbered copies (0.py, 1.ipynb...) are never named
        text = json.dumps(report)
        assert not [name for name in NUMBERED if re.search(rf"(?<![\w-]){re.escape(name)}", text)], text


def test_a_hostile_name_is_shown_neutralised_and_bounded_and_never_touches_the_file_system(
    tmp_path: Path,
) -> None:
    reports = _grade_refused(_canvas_zip(tmp_path / "download" / "submissions.zip"), tmp_path / "out")
    shown = reports["3004"]["submission"]
    assert shown == file_name(f"{HOSTILE_ZIP}/{HOSTILE_FILE}")
    assert isinstance(shown, str) and len(shown) == MAX_FILE_NAME_CHARS
    assert shown.startswith("'=cmd|' -C calc'!A0\ufffd]0;owned\ufffd\ufffdgpjx")
    assert shown.endswith("…")
    assert str(reports["3004"]["submission_error"]).startswith(f"{shown} is not valid Python")
    written = [path.name for path in tmp_path.rglob("*")]
    assert not [name for name in written if "cmd" in name or "owned" in name or len(name) > 100], written


@pytest.mark.parametrize(
    ("given", "shown"),
    [
        ("policy_function_iteration.py", "policy_function_iteration.py"),
        ("alice.zip/lab/opengym.py", "opengym.py"),
        ("../../etc/passwd.py", "passwd.py"),
        ("lab\\..\\..\\evil.py", "evil.py"),
        ("=HYPERLINK(1).py", "'=HYPERLINK(1).py"),
        ("＝cmd.py", "'＝cmd.py"),
        ("a\nb\r\x00c.py", "a b \ufffdc.py"),
        ("rtl\u202eyp.exe", "rtl\ufffdyp.exe"),
        ("x" * 10_000 + ".py", "x" * (MAX_FILE_NAME_CHARS - 1) + "…"),
        ("=" + "x" * 10_000, "'=" + "x" * (MAX_FILE_NAME_CHARS - 3) + "…"),
        ("", "(blank)"),
        ("folder/", "folder"),
    ],
    ids=[
        "plain",
        "in-a-zip",
        "climbing",
        "backslashes",
        "formula",
        "fullwidth-formula",
        "controls",
        "bidi",
        "long",
        "long-formula",
        "empty",
        "trailing-slash",
    ],
)
def test_file_name_shows_the_last_component_neutralised_and_bounded(given: str, shown: str) -> None:
    assert file_name(given) == shown


def test_a_folder_download_keeps_its_files_own_names(tmp_path: Path) -> None:
    folder = tmp_path / "download"
    (folder / "ada").mkdir(parents=True)
    (folder / "ada" / "opengym.py").write_bytes(BROKEN)
    (folder / "bob").mkdir()
    (folder / "bob" / "opengym.py").write_bytes(SOLUTION)
    download = discover(folder, rule=RULE, scratch=tmp_path / "scratch", due=DUE)
    names = command.file_names_of(download.submissions)
    assert {path: name for path, name in names.items()} == {
        s.graded_file.path: s.graded_file.path.name for s in download.submissions if s.graded_file
    }
    assert set(names.values()) == {"opengym.py"}
    out = tmp_path / "out"
    ada = next(s for s in download.submissions if s.identity == "ada")
    assert ada.graded_file is not None
    with_names = grade_many([ada.graded_file.path], out, seed=5, only=ONLY, file_names=names).reports[0]
    without = grade_many([ada.graded_file.path], tmp_path / "out2", seed=5, only=ONLY).reports[0]
    assert with_names.graded_view() == without.graded_view()
    assert with_names.submission == "opengym.py"


def test_the_similarity_check_names_a_zips_files_as_the_download_does(tmp_path: Path) -> None:
    download = discover(
        _canvas_zip(tmp_path / "download" / "submissions.zip"),
        rule=RULE,
        scratch=tmp_path / "scratch",
        due=DUE,
    )
    report = run_similarity(sources_of(download), workers=1).report
    left_out = {entry.identity: entry.file for entry in report.unreadable}
    assert left_out["3001"] == BROKEN_ENTRY
    assert left_out["3002"] == NOTEBOOK_ENTRY
    assert left_out["3004"] == file_name(HOSTILE_FILE)
    reasons = " ".join(entry.reason for entry in report.unreadable)
    assert f"{BROKEN_ENTRY} is not valid Python" in reasons
    assert f"{NOTEBOOK_ENTRY} " in reasons


RAISES_ENTRY = "raiserosa_3005_7005_opengym.py"


@pytest.mark.slow  # a grading through the sandbox
def test_gymgrade_grade_names_a_canvas_zips_files_as_the_download_does(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The real command: the honest file, the broken one, the notebook and a file raising at import (whose
    message comes from the sandbox) are each reported under the name the download gives them."""
    config = write_config(tmp_path / "fast.toml", FAST_OVERRIDES)
    download = _canvas_zip(tmp_path / "download" / "submissions.zip")
    with zipfile.ZipFile(download, "a") as bundle:
        bundle.writestr(RAISES_ENTRY, b"raise RuntimeError('boom at import')\n")
    out = tmp_path / "out"
    argv = ["grade", str(download), "--out", str(out), "--only", "random_blackjack", "--seed", "11"]
    argv += ["--config", str(config), "--allow-weak-isolation", "--due", DUE.isoformat()]
    assert cli.main(argv) == 0
    capsys.readouterr()
    reports = {path.stem: json.loads(path.read_text("utf-8")) for path in out.glob("*.json")}
    assert {identity: report["submission"] for identity, report in reports.items()} == {
        "3001": BROKEN_ENTRY,
        "3002": NOTEBOOK_ENTRY,
        "3003": HONEST_ENTRY,
        "3004": file_name(HOSTILE_FILE),
        "3005": RAISES_ENTRY,
    }
    assert reports["3003"]["score"] == reports["3003"]["max_score"]
    assert str(reports["3001"]["submission_error"]).startswith(f"{BROKEN_ENTRY} is not valid Python")
    (raised,) = reports["3005"]["problems"]
    feedback = str(raised["feedback"])
    assert f"importing {RAISES_ENTRY} raised RuntimeError: boom at import" in feedback
    assert f'File "/submission/{RAISES_ENTRY}", line 1, in <module>' in feedback
    assert not re.search(r"(?<![\w-])\d+\.py", feedback), feedback


def test_edition_detection_names_a_zips_files_as_the_download_does(tmp_path: Path) -> None:
    from grader.lab.editions.per_submission import class_editions

    download = discover(
        _canvas_zip(tmp_path / "download" / "submissions.zip"),
        rule=RULE,
        scratch=tmp_path / "scratch",
        due=DUE,
    )
    files = {s.identity: s.graded_file.path for s in download.submissions if s.graded_file}
    shown = command.file_names_of(download.submissions)
    lines = class_editions(files, {identity: shown[path] for identity, path in files.items()}).lines()
    assert any(f"{BROKEN_ENTRY} could not be read as Python" in line for line in lines), lines
    assert not any(re.search(r"(?<![\w-])\d+\.py", line) for line in lines), lines
