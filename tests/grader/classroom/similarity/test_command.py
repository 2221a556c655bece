"""`gymgrade similarity` end to end: the CSV, the page (rendered by a real Chromium) and what it prints."""

from __future__ import annotations

import csv
import shutil
from pathlib import Path

import pytest

from grader.classroom.similarity.html_output import CSP
from grader.cli import main

CORPUS = Path(__file__).resolve().parents[4] / "submissions" / "similarity"
CHROMIUM = "/usr/bin/chromium"


@pytest.fixture(scope="module")
def out(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("similarity")
    klass = folder / "class"
    shutil.copytree(CORPUS / "class", klass)
    (klass / "<img src=x onerror=alert(1)>.py").write_text(
        (CORPUS / "class" / "h07_terse.py").read_text(encoding="utf-8"), encoding="utf-8"
    )
    (klass / "broken.py").write_bytes(b"def f(:\n")
    argv = [
        "similarity",
        str(klass),
        "--reference",
        str(CORPUS / "references" / "public_2021"),
        "--reference",
        str(CORPUS / "references" / "public_2022"),
        "--out",
        str(folder / "out"),
        "--cache",
        str(folder / "cache"),
    ]
    assert main(argv) == 0
    return folder / "out"


def test_the_csv_has_one_row_per_flagged_pair_ranked(out: Path) -> None:
    with (out / "similarity.csv").open(encoding="utf-8", newline="") as stream:
        rows = list(csv.DictReader(stream))
    pairs = [frozenset((row["a"], row["b"])) for row in rows]
    assert frozenset(("h07_terse", "<img src=x onerror=alert(1)>")) in pairs
    assert frozenset(("omar_haddad", "public_2021/opengym_solution.py")) in pairs
    assert len(rows) == 10
    scores = [float(row["score"]) for row in rows]
    assert scores == sorted(scores, reverse=True)


def test_the_page_is_self_contained_escapes_student_names_and_never_accuses(out: Path) -> None:
    page = (out / "similarity.html").read_text(encoding="utf-8")
    assert f'content="{CSP}"' in page
    assert "<img" not in page and "&lt;img src=x onerror=alert(1)&gt;" in page
    assert "plagiari" not in page.lower() and "cheat" not in page.lower()
    assert "broken.py is not valid Python (line 1)" in page
    assert "http://" not in page and "https://" not in page


def test_the_command_says_what_it_found(out: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["similarity", str(CORPUS / "class"), "--out", str(out.parent / "again"), "--no-cache"]) == 0
    printed = capsys.readouterr().out
    assert printed.startswith(
        "Compared 22 students with each other: 8 pairs flagged for reading, in 6 groups.\n"
    )


def test_a_missing_class_folder_exits_2_with_what_to_pass(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["similarity", str(tmp_path / "nowhere"), "--out", str(tmp_path / "out")]) == 2
    assert "expected a class folder" in capsys.readouterr().err


@pytest.mark.browser
def test_chromium_renders_the_pairs_side_by_side_under_the_page_policy(out: Path) -> None:
    if shutil.which(CHROMIUM) is None:
        pytest.skip(f"Chromium is not installed at {CHROMIUM} (apt-get install -y chromium)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="pip install playwright")
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"], headless=True)
        try:
            page = browser.new_page()
            console: list[str] = []
            page.on("console", lambda message: console.append(message.text))
            page.goto((out / "similarity.html").as_uri())
            columns = page.eval_on_selector(".sides", "node => getComputedStyle(node).gridTemplateColumns")
            sides = page.eval_on_selector_all(
                ".pair", "nodes => nodes.map(n => n.querySelectorAll('.side pre').length)"
            )
            rows = page.eval_on_selector_all("#pairs + table tr", "rows => rows.length")
            dialogs: list[str] = []
            page.on("dialog", lambda dialog: dialogs.append(dialog.message))
        finally:
            browser.close()
    assert (
        len(columns.split()) == 2
    )  # the stylesheet applied (its CSP hash matches): two columns side by side
    assert len(sides) == 10 and all(count >= 2 and count % 2 == 0 for count in sides)
    assert rows == 11
    assert console == [] and dialogs == []


def test_grading_reports_add_shared_wrong_results_as_evidence(tmp_path: Path) -> None:
    from grader.report import ProblemResult, Report

    def report(name: str, status: str) -> str:
        problems = [
            ProblemResult(
                id=problem,
                title=problem,
                status=status,  # type: ignore[arg-type]
                score=0.0,
                max_score=1.0,
                feedback="",
                measurements={"returned": value},
            )
            for problem, value in (("blackjack", 0.0913), ("car", 201), ("taxi", -812.25))
        ]
        return Report(
            submission=f"{name}.py",
            sha256="0" * 64,
            seed=5,
            gymnasium_version="1",
            grader_version="1",
            score=0.0,
            max_score=3.0,
            problems=problems,
        ).to_json()

    reports = tmp_path / "graded"
    reports.mkdir()
    (reports / "h06_functional.json").write_text(report("h06_functional", "failed"), encoding="utf-8")
    (reports / "h09_counter.json").write_text(report("h09_counter", "failed"), encoding="utf-8")
    (reports / "h07_terse.json").write_text(report("h07_terse", "passed"), encoding="utf-8")
    argv = ["similarity", str(CORPUS / "class"), "--reports", str(reports), "--out", str(tmp_path / "out")]
    assert main([*argv, "--no-cache"]) == 0
    with (tmp_path / "out" / "similarity.csv").open(encoding="utf-8", newline="") as stream:
        rows = {frozenset((row["a"], row["b"])): row for row in csv.DictReader(stream)}
    shared = rows[frozenset(("h06_functional", "h09_counter"))]
    assert shared["evidence"].count("the same wrong result on") == 3
    assert not any("h07_terse" in pair for pair in rows)


HOSTILE_NAMES = {
    "rtl": "\u202eecila",
    "escape": "\x1b]0;owned\x07\x1b[2Jmallory",
    "c1": "\x9b31mtrudy",
    "newline": "eve\n  refused alice",
}


def test_names_that_reorder_retitle_or_forge_lines_are_inert_in_every_output(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Hostile: identities with a right-to-left override, escape sequences, a C1 control and a newline copy
    one another's code; the page, the CSV, the JSON and the printed summary show them inert."""
    klass = tmp_path / "class"
    klass.mkdir()
    for name in HOSTILE_NAMES.values():
        (klass / f"{name}.py").write_text((CORPUS / "class" / "h07_terse.py").read_text(encoding="utf-8"))
    (klass / "\u202ebroken.py").write_bytes(b"def f(:\n")
    assert main(["similarity", str(klass), "--out", str(tmp_path / "out"), "--no-cache"]) == 0
    printed = capsys.readouterr().out
    page = (tmp_path / "out" / "similarity.html").read_text(encoding="utf-8")
    table = (tmp_path / "out" / "similarity.csv").read_text(encoding="utf-8")
    summary = (tmp_path / "out" / "similarity.json").read_text(encoding="utf-8")
    unsafe = ["\x1b", "\x07", "\x9b", "\u202e"]
    for output in (printed, page, table, summary):
        assert [character for character in unsafe if character in output] == []
    assert "<bdi>\ufffdecila</bdi>" in page, "shown as written, never turned around into 'alice'"
    assert "\n  refused alice" not in printed and "eve refused alice" in page
    assert summary.isascii() and "\\u202eecila" in summary, "the JSON keeps the identity, escaped"
    assert "left out \ufffdbroken.py (\ufffdbroken): \ufffdbroken.py is not valid Python" in printed
