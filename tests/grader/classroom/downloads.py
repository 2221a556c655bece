"""Realistic class downloads of every layout, built in a test's folder (also used by bench/layouts.py).

Each has several students, a resubmission, a late one, a group, a student with extra files (helpers, tests,
a checkpoint), a file nobody can be named for, and a symbolic link; ``Expected`` says what discovery must
make of it.
"""

from __future__ import annotations

import json
import os
import stat
import zipfile
from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import UTC, datetime, timedelta
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
SOLUTION = (ROOT / "submissions" / "gymnasium_complete.py").read_bytes()
HELPER = b"def clamp(x, low, high):\n    return max(low, min(high, x))\n"
TEST_FILE = (
    b"from opengym import random_blackjack\n\ndef test_rate():\n    assert random_blackjack(10) >= 0\n"
)
DUE = datetime(2026, 3, 1, 23, 59, tzinfo=UTC)
ON_TIME = DUE - timedelta(days=1)
LATE = DUE + timedelta(hours=5)


@dataclass
class Expected:
    """What discovering a built download must find.

    Attributes:
        path: What to pass to ``discover`` (the folder or the zip).
        layout: The layout it must be recognised as.
        graded: Identity -> the graded file's path in the download (None: nothing graded).
        late: Identities that are late (with ``due=DUE``).
        groups: Identity -> member identities, for group submissions.
        refused: Paths in the download that must be refused.
        unattributed: Paths in the download nobody can be named for.
        names: Identity -> the name the source gives.
    """

    path: Path
    layout: str
    graded: dict[str, str | None] = field(default_factory=dict)
    late: set[str] = field(default_factory=set)
    groups: dict[str, tuple[str, ...]] = field(default_factory=dict)
    refused: list[str] = field(default_factory=list)
    unattributed: list[str] = field(default_factory=list)
    names: dict[str, str] = field(default_factory=dict)


def _write(path: Path, data: bytes) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(data)


def _symlink(path: Path, target: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    os.symlink(target, path)


def _notebook(source: bytes) -> bytes:
    cells = [{"cell_type": "code", "metadata": {}, "execution_count": None, "outputs": [],
              "source": source.decode().splitlines(keepends=True)}]  # fmt: skip
    return json.dumps({"cells": cells, "metadata": {}, "nbformat": 4, "nbformat_minor": 5}).encode()


def plain(root: Path, students: int = 4) -> Expected:
    """``class/{student}/...`` folders, one flat file, a resubmission kept in ``old/``, a symlink."""
    folder = root / "class"
    expected = Expected(folder, "plain")
    for number in range(students):
        who = f"student{number:03d}"
        _write(folder / who / "opengym.py", SOLUTION)
        expected.graded[who] = f"{who}/opengym.py"
    _write(folder / "bob" / "opengym.py", SOLUTION)
    _write(folder / "bob" / "old" / "opengym.py", b"def random_blackjack(n):\n    return 0\n")
    expected.graded["bob"] = "bob/opengym.py"
    _write(folder / "carol" / "my lab.ipynb", _notebook(SOLUTION))
    expected.graded["carol"] = "carol/my lab.ipynb"
    _write(folder / "dan" / "helpers.py", HELPER)
    _write(folder / "dan" / "solution.py", SOLUTION)
    _write(folder / "dan" / "test_solution.py", TEST_FILE)
    _write(folder / "dan" / ".ipynb_checkpoints" / "solution-checkpoint.ipynb", _notebook(SOLUTION))
    expected.graded["dan"] = "dan/solution.py"
    _write(folder / "0042.py", SOLUTION)
    expected.graded["0042"] = "0042.py"
    _write(folder / "=1+2.py", SOLUTION)
    expected.graded["=1+2"] = "=1+2.py"
    _write(folder / "notes.txt", b"grading notes\n")
    expected.unattributed.append("notes.txt")
    _write(folder / "eve" / "README.md", b"see my file\n")
    _symlink(folder / "eve" / "opengym.py", "/etc/passwd")
    expected.graded["eve"] = None
    expected.refused.append("eve/opengym.py")
    return expected


def canvas(root: Path, students: int = 4) -> Expected:
    """A Canvas "Download Submissions" zip as it comes: flat names, a re-upload renamed ``-1``, ``_LATE``, a
    group's file, a student's zip (with ``__MACOSX``), a stray file, a symlink entry and a ``../`` entry."""
    expected = Expected(root / "submissions.zip", "canvas")
    entries: list[tuple[str, bytes]] = []
    attachment = 5000
    for number in range(students):
        user = str(1000 + number)
        attachment += 1
        entries.append((f"student{number}_{user}_{attachment}_opengym.py", SOLUTION))
        expected.graded[user] = f"student{number}_{user}_{attachment}_opengym.py"
    entries.append(("lovelaceada_2001_6001_opengym.py", b"def random_blackjack(n):\n    return 0\n"))
    entries.append(("lovelaceada_2001_6007_opengym-1.py", SOLUTION))
    expected.graded["2001"] = "lovelaceada_2001_6007_opengym-1.py"
    expected.names["2001"] = "lovelaceada"
    entries.append(("obrienbob_LATE_2002_6002_opengym.py", SOLUTION))
    expected.graded["2002"] = "obrienbob_LATE_2002_6002_opengym.py"
    expected.late.add("2002")
    entries.append(("teamrocket_2003_6003_opengym.py", SOLUTION))
    expected.graded["2003"] = "teamrocket_2003_6003_opengym.py"
    entries += [
        ("duboischloe_2004_6004_helpers.py", HELPER),
        ("duboischloe_2004_6005_test_opengym.py", TEST_FILE),
        ("duboischloe_2004_6006_lab1.py", SOLUTION),
    ]
    expected.graded["2004"] = "duboischloe_2004_6006_lab1.py"
    inner = _zip_bytes([("lab/opengym.py", SOLUTION), ("__MACOSX/lab/._opengym.py", b"\x00\x05")])
    entries.append(("zhangwei_2005_6008_submission.zip", inner))
    expected.graded["2005"] = "zhangwei_2005_6008_submission.zip/lab/opengym.py"
    entries.append(("grades_from_last_year.csv", b"a,b\n"))
    expected.unattributed.append("grades_from_last_year.csv")
    root.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(expected.path, "w", zipfile.ZIP_DEFLATED) as bundle:
        for name, data in entries:
            bundle.writestr(name, data)
        link = zipfile.ZipInfo("malloryeve_2006_6009_opengym.py")
        link.external_attr = (stat.S_IFLNK | 0o777) << 16
        bundle.writestr(link, "/etc/passwd")
        bundle.writestr("../../escaped_2007_6010_opengym.py", SOLUTION)
    expected.refused += ["malloryeve_2006_6009_opengym.py", "../../escaped_2007_6010_opengym.py"]
    expected.graded["2006"] = None  # a student whose only file is refused still gets a row saying so
    return expected


def _zip_bytes(entries: list[tuple[str, bytes]]) -> bytes:
    import io

    stream = io.BytesIO()
    with zipfile.ZipFile(stream, "w", zipfile.ZIP_DEFLATED) as bundle:
        for name, data in entries:
            bundle.writestr(name, data)
    return stream.getvalue()


def _yaml_time(moment: datetime) -> str:
    return moment.strftime("%Y-%m-%d %H:%M:%S.%f000 +00:00")


def gradescope(root: Path, students: int = 4) -> Expected:
    """``assignment_{id}_export/``: metadata with Ruby-symbol keys, a pair's submission, history, a late
    one, a
    folder not in the metadata, a symlinked file."""
    base = root / "assignment_4242_export"
    expected = Expected(root, "gradescope")
    records: list[str] = []

    def record(folder: str, submitters: list[tuple[str, str, str]], when: datetime, history: int = 0) -> None:
        lines = [f"{folder}:", "  :submitters:"]
        for name, sid, email in submitters:
            lines += [f"  - :name: {json.dumps(name)}", f"    :sid: '{sid}'", f"    :email: {email}"]
        lines.append(f"  :created_at: {_yaml_time(when)}")
        lines.append("  :score: 0.0")
        if history:
            lines.append("  :history:")
            for attempt in range(history):
                lines += [
                    f"  - :id: {700 + attempt}",
                    f"    :created_at: {_yaml_time(when - timedelta(days=attempt + 1))}",
                ]
        else:
            lines.append("  :history: []")
        records.append("\n".join(lines))

    for number in range(students):
        sid = f"00{3100 + number}"
        folder = f"submission_{20000 + number}"
        _write(base / folder / "opengym.py", SOLUTION)
        record(folder, [(f"Student {number}", sid, f"s{number}@uni.edu")], ON_TIME)
        expected.graded[sid] = f"assignment_4242_export/{folder}/opengym.py"
    _write(base / "submission_9101" / "opengym.py", SOLUTION)
    record(
        "submission_9101",
        [("Ada Lovelace", "000101", "ada@uni.edu"), ("Bob Brown", "000102", "bob@uni.edu")],
        ON_TIME,
        history=2,
    )
    expected.graded["000101+000102"] = "assignment_4242_export/submission_9101/opengym.py"
    expected.groups["000101+000102"] = ("000101", "000102")
    _write(base / "submission_9102" / "opengym.py", SOLUTION)
    record("submission_9102", [("Chloé Dubois", "000103", "chloe@uni.edu")], LATE)
    expected.graded["000103"] = "assignment_4242_export/submission_9102/opengym.py"
    expected.late.add("000103")
    _write(base / "submission_9103" / "src" / "agent.py", SOLUTION)
    _write(base / "submission_9103" / "src" / "utils.py", HELPER)
    _write(base / "submission_9103" / "tests" / "agent_test.py", TEST_FILE)
    record("submission_9103", [("Dan Ng", "000104", "dan@uni.edu")], ON_TIME)
    expected.graded["000104"] = "assignment_4242_export/submission_9103/src/agent.py"
    _symlink(base / "submission_9104" / "opengym.py", "../submission_20000/opengym.py")
    record("submission_9104", [("Eve Mallory", "000105", "eve@uni.edu")], ON_TIME)
    expected.graded["000105"] = None
    expected.refused.append("assignment_4242_export/submission_9104/opengym.py")
    _write(base / "submission_9999" / "opengym.py", SOLUTION)
    expected.unattributed.append("assignment_4242_export/submission_9999/opengym.py")
    _write(base / "submission_metadata.yml", ("\n".join(records) + "\n").encode())
    return expected


def github_classroom(root: Path, students: int = 4) -> Expected:
    """``lab-1-submissions/lab-1-{username}/``: repositories with .git, a team's, tests and helpers, a stray
    README, a symlink, and the classroom roster beside it (``roster.csv``)."""
    folder = root / "lab-1-submissions"
    expected = Expected(folder, "github-classroom")
    roster = ["identifier,github_username,github_id,name"]
    for number in range(students):
        user = f"octo-cat{number}"
        _write(folder / f"lab-1-{user}" / "opengym.py", SOLUTION)
        _write(folder / f"lab-1-{user}" / ".git" / "HEAD", b"ref: refs/heads/main\n")
        expected.graded[user] = f"lab-1-{user}/opengym.py"
        roster.append(f"s{number:04d}@uni.edu,{user},{500 + number},Student {number}")
    _write(folder / "lab-1-team-rocket" / "opengym.ipynb", _notebook(SOLUTION))
    expected.graded["team-rocket"] = "lab-1-team-rocket/opengym.ipynb"
    _write(folder / "lab-1-dancer" / "agent.py", SOLUTION)
    _write(folder / "lab-1-dancer" / "helpers.py", HELPER)
    _write(folder / "lab-1-dancer" / "tests" / "test_agent.py", TEST_FILE)
    _write(folder / "lab-1-dancer" / ".github" / "classroom" / "autograding.json", b"{}")
    expected.graded["dancer"] = "lab-1-dancer/agent.py"
    _write(folder / "lab-1-latecomer" / "opengym.py", SOLUTION)
    expected.graded["latecomer"] = "lab-1-latecomer/opengym.py"
    _symlink(folder / "lab-1-mallory" / "opengym.py", "/etc/hostname")
    _write(folder / "lab-1-mallory" / "README.md", b"hi\n")
    expected.graded["mallory"] = None
    expected.refused.append("lab-1-mallory/opengym.py")
    _write(folder / "README.md", b"cloned by gh classroom\n")
    expected.unattributed.append("README.md")
    roster.append("absent@uni.edu,never-submitted,999,Absent Student")
    (root / "roster.csv").write_text("\n".join(roster) + "\n", encoding="utf-8")
    return expected


def moodle(root: Path, students: int = 4) -> Expected:
    """Moodle "Download all submissions": per-participant folders, one flat file, online text, a stray index
    file, a symlink."""
    folder = root / "moodle"
    expected = Expected(folder, "moodle")
    for number in range(students):
        pid = str(81000 + number)
        prefix = f"Student Number{number}_{pid}_assignsubmission_file_"
        _write(folder / prefix / "opengym.py", SOLUTION)
        expected.graded[pid] = f"{prefix}/opengym.py"
        expected.names[pid] = f"Student Number{number}"
    _write(folder / "Ada Lovelace_82001_assignsubmission_file_" / "opengym (1).py", SOLUTION)
    _write(folder / "Ada Lovelace_82001_assignsubmission_onlinetext_" / "onlinetext.html", b"<p>done</p>")
    expected.graded["82001"] = "Ada Lovelace_82001_assignsubmission_file_/opengym (1).py"
    _write(folder / "Bob Brown_82002_assignsubmission_file_opengym.py", SOLUTION)
    expected.graded["82002"] = "Bob Brown_82002_assignsubmission_file_opengym.py"
    chloe = "Chloé Dubois_82003_assignsubmission_file_"
    _write(folder / chloe / "lab_solution.py", SOLUTION)
    _write(folder / chloe / "helpers.py", HELPER)
    _write(folder / chloe / "test_lab_solution.py", TEST_FILE)
    expected.graded["82003"] = f"{chloe}/lab_solution.py"
    _symlink(folder / "Eve Mallory_82004_assignsubmission_file_" / "opengym.py", "/etc/passwd")
    _write(folder / "Eve Mallory_82004_assignsubmission_file_" / "notes.txt", b"my answers\n")
    expected.graded["82004"] = None
    expected.refused.append("Eve Mallory_82004_assignsubmission_file_/opengym.py")
    _write(folder / "index.html", b"<html></html>")
    expected.unattributed.append("index.html")
    return expected


def nbgrader(root: Path, students: int = 4) -> Expected:
    """``submitted/{student}/ps1/`` with timestamps (one late), checkpoints and helpers, a stray file, a
    symlinked notebook."""
    course = root / "course"
    expected = Expected(course, "nbgrader")
    submitted = course / "submitted"
    for number in range(students):
        sid = f"{number:05d}"
        _write(submitted / sid / "ps1" / "opengym.ipynb", _notebook(SOLUTION))
        _write(
            submitted / sid / "ps1" / "timestamp.txt", ON_TIME.strftime("%Y-%m-%d %H:%M:%S.%f UTC").encode()
        )
        expected.graded[sid] = f"submitted/{sid}/ps1/opengym.ipynb"
    _write(submitted / "late01" / "ps1" / "gymnasium.ipynb", _notebook(SOLUTION))
    _write(submitted / "late01" / "ps1" / "timestamp.txt", LATE.strftime("%Y-%m-%d %H:%M:%S.%f UTC").encode())
    expected.graded["late01"] = "submitted/late01/ps1/gymnasium.ipynb"
    expected.late.add("late01")
    _write(submitted / "extra01" / "ps1" / "opengym.ipynb", _notebook(SOLUTION))
    _write(
        submitted / "extra01" / "ps1" / ".ipynb_checkpoints" / "opengym-checkpoint.ipynb", _notebook(SOLUTION)
    )
    _write(submitted / "extra01" / "ps1" / "helpers.py", HELPER)
    _write(
        submitted / "extra01" / "ps1" / "timestamp.txt", ON_TIME.strftime("%Y-%m-%d %H:%M:%S.%f UTC").encode()
    )
    expected.graded["extra01"] = "submitted/extra01/ps1/opengym.ipynb"
    _symlink(submitted / "mallory" / "ps1" / "opengym.ipynb", "/etc/passwd")
    _write(
        submitted / "mallory" / "ps1" / "timestamp.txt", ON_TIME.strftime("%Y-%m-%d %H:%M:%S.%f UTC").encode()
    )
    expected.graded["mallory"] = None
    expected.refused.append("submitted/mallory/ps1/opengym.ipynb")
    _write(submitted / "README.txt", b"nbgrader collect\n")
    expected.unattributed.append("submitted/README.txt")
    return expected


def blackboard(root: Path, students: int = 4) -> Expected:
    """Blackboard's flat ``{assignment}_{username}_attempt_{time}_{file}`` files with attempt ``.txt``s, two
    attempts for one student, a late one, extra files, a stray file, a symlink."""
    folder = root / "gradebook_Lab 1"
    expected = Expected(folder, "blackboard")

    def attempt(user: str, name: str, when: datetime, files: dict[str, bytes]) -> str:
        stamp = when.strftime("%Y-%m-%d-%H-%M-%S")
        _write(
            folder / f"Lab 1_{user}_attempt_{stamp}.txt",
            f"Name: {name} ({user})\nAssignment: Lab 1\n".encode(),
        )
        for original, data in files.items():
            _write(folder / f"Lab 1_{user}_attempt_{stamp}_{original}", data)
        return stamp

    for number in range(students):
        user = f"stu{number:04d}"
        stamp = attempt(user, f"Student {number}", ON_TIME, {"opengym.py": SOLUTION})
        expected.graded[user] = f"Lab 1_{user}_attempt_{stamp}_opengym.py"
        expected.names[user] = f"Student {number}"
    attempt("a_lovelace", "Ada Lovelace", ON_TIME - timedelta(days=2), {"opengym.py": b"x = 1\n"})
    stamp = attempt("a_lovelace", "Ada Lovelace", ON_TIME, {"opengym.py": SOLUTION})
    expected.graded["a_lovelace"] = f"Lab 1_a_lovelace_attempt_{stamp}_opengym.py"
    stamp = attempt("bbrown", "Bob Brown", LATE, {"opengym.py": SOLUTION})
    expected.graded["bbrown"] = f"Lab 1_bbrown_attempt_{stamp}_opengym.py"
    expected.late.add("bbrown")
    stamp = attempt(
        "cdubois",
        "Chloé Dubois",
        ON_TIME,
        {"main.py": SOLUTION, "helpers.py": HELPER, "test_main.py": TEST_FILE},
    )
    expected.graded["cdubois"] = f"Lab 1_cdubois_attempt_{stamp}_main.py"
    stamp = ON_TIME.strftime("%Y-%m-%d-%H-%M-%S")
    _symlink(folder / f"Lab 1_emallory_attempt_{stamp}_opengym.py", "/etc/passwd")
    expected.refused.append(f"Lab 1_emallory_attempt_{stamp}_opengym.py")
    expected.graded["emallory"] = None
    _write(folder / "Lab 1_instructions.pdf", b"%PDF-1.4\n")
    expected.unattributed.append("Lab 1_instructions.pdf")
    return expected


BUILDERS: dict[str, Callable[[Path, int], Expected]] = {
    "plain": plain,
    "canvas": canvas,
    "gradescope": gradescope,
    "github-classroom": github_classroom,
    "moodle": moodle,
    "nbgrader": nbgrader,
    "blackboard": blackboard,
}
"""A builder per layout name."""
