"""Every layout's submission time, from what its download holds: Gradescope's metadata, a GitHub Classroom
clone's checked-out commit (loose and packed, never through a link), nbgrader's and Blackboard's stamps,
Canvas's late mark without hours, and the times an instructor gives (a plain CSV, a Canvas submissions CSV,
Moodle's grading worksheet)."""

from __future__ import annotations

import os
import subprocess
from datetime import UTC, datetime, timedelta, timezone
from pathlib import Path

import pytest

from grader.classroom import GradedFileRule, discover
from grader.classroom.errors import LatePolicyError
from grader.classroom.git_commit import commit_time
from grader.classroom.submitted_at import parse_submitted_at

from .downloads import BUILDERS, DUE, LATE, ON_TIME

RULE = GradedFileRule(functions=("random_blackjack", "blackjack", "cartpole", "car", "taxi", "find_qvalues"))
EST = timezone(timedelta(hours=-5))


def _times(layout: str, tmp_path: Path) -> dict[str, tuple[datetime | None, bool | None]]:
    expected = BUILDERS[layout](tmp_path / "download", 2)
    download = discover(expected.path, rule=RULE, scratch=tmp_path / "scratch", due=DUE)
    return {s.identity: (s.submitted_at, s.late) for s in download.submissions}


@pytest.mark.parametrize(
    ("layout", "identity", "submitted_at", "late"),
    [
        ("gradescope", "000103", LATE, True),
        ("gradescope", "003100", ON_TIME, False),
        ("nbgrader", "late01", LATE, True),
        ("blackboard", "bbrown", LATE.replace(tzinfo=None), True),
        ("blackboard", "stu0000", ON_TIME.replace(tzinfo=None), False),
        ("canvas", "2002", None, True),
        ("canvas", "1000", None, False),
        ("moodle", "81000", None, None),
        ("plain", "student000", None, None),
    ],
    ids=["gradescope-late", "gradescope-on-time", "nbgrader-timestamp", "blackboard-file-name",
         "blackboard-on-time", "canvas-late-mark-no-hours", "canvas-no-mark", "moodle-none-in-the-download", "plain-none"],  # noqa: E501
)  # fmt: skip
def test_each_layouts_download_gives_its_time(
    layout: str, identity: str, submitted_at: datetime | None, late: bool | None, tmp_path: Path
) -> None:
    times = _times(layout, tmp_path)
    assert times[identity] == (submitted_at, late), sorted(times)


def _git(repository: Path, *args: str, when: datetime) -> None:
    stamp = when.isoformat()
    environment = {**os.environ, "GIT_AUTHOR_DATE": stamp, "GIT_COMMITTER_DATE": stamp,
                   "GIT_AUTHOR_NAME": "s", "GIT_AUTHOR_EMAIL": "s@x", "GIT_COMMITTER_NAME": "s",
                   "GIT_COMMITTER_EMAIL": "s@x", "GIT_CONFIG_GLOBAL": os.devnull, "GIT_CONFIG_NOSYSTEM": "1"}  # fmt: skip  # noqa: E501
    subprocess.run(["git", "-C", str(repository), *args], check=True, capture_output=True, env=environment)


def _repository(path: Path, commits: list[datetime], *, packed: bool) -> Path:
    path.mkdir(parents=True)
    _git(path, "init", "-q", "-b", "main", when=commits[0])
    for number, when in enumerate(commits):
        (path / "opengym.py").write_text(f"# version {number}\n", encoding="utf-8")
        _git(path, "add", "opengym.py", when=when)
        _git(path, "commit", "-q", "-m", f"v{number}", when=when)
    if packed:
        _git(path, "gc", "-q", "--prune=now", when=commits[-1])
        assert not list((path / ".git" / "objects").glob("??/*")), "every object is packed"
        assert not (path / ".git" / "refs" / "heads" / "main").exists(), "the ref is packed"
    return path


@pytest.mark.parametrize("packed", [False, True], ids=["loose", "packed"])
def test_a_clones_time_is_its_checked_out_commits(packed: bool, tmp_path: Path) -> None:
    late = datetime(2026, 3, 2, 9, 30, tzinfo=EST)
    folder = tmp_path / "lab-1-submissions"
    _repository(folder / "lab-1-alice", [ON_TIME - timedelta(days=3), ON_TIME], packed=packed)
    _repository(folder / "lab-1-bob", [ON_TIME, late], packed=packed)
    download = discover(folder, rule=RULE, scratch=tmp_path / "scratch", due=DUE)
    assert download.layout == "github-classroom"
    assert {s.identity: (s.submitted_at, s.late) for s in download.submissions} == {
        "alice": (ON_TIME, False),
        "bob": (late, True),
    }


def test_a_detached_head_names_its_commit(tmp_path: Path) -> None:
    first = ON_TIME - timedelta(days=1)
    repository = _repository(tmp_path / "r", [first, ON_TIME], packed=False)
    _git(repository, "checkout", "-q", "--detach", "HEAD~1", when=ON_TIME)
    assert commit_time(repository) == first


@pytest.mark.parametrize(
    "tamper",
    ["head-climbs-out", "head-is-a-link", "git-is-a-link", "git-is-a-file", "ref-is-garbage",
     "object-is-not-zlib", "no-git"],
)  # fmt: skip
def test_a_tampered_git_folder_gives_no_time_and_reads_nothing_outside(tamper: str, tmp_path: Path) -> None:
    repository = _repository(tmp_path / "r", [ON_TIME], packed=False)
    git = repository / ".git"
    outside = _repository(tmp_path / "elsewhere", [LATE], packed=False) / ".git"
    if tamper == "head-climbs-out":
        (git / "HEAD").write_bytes(b"ref: refs/../../../elsewhere/.git/refs/heads/main\n")
    elif tamper == "head-is-a-link":
        (git / "HEAD").unlink()
        (git / "HEAD").symlink_to(outside / "HEAD")
        (git / "refs" / "heads" / "main").unlink()
        (git / "refs" / "heads" / "main").symlink_to(outside / "refs" / "heads" / "main")
    elif tamper in ("git-is-a-link", "git-is-a-file", "no-git"):
        subprocess.run(["rm", "-rf", str(git)], check=True)
        if tamper == "git-is-a-link":
            git.symlink_to(outside)
        elif tamper == "git-is-a-file":
            git.write_text(f"gitdir: {outside}\n", encoding="utf-8")
    elif tamper == "ref-is-garbage":
        (git / "refs" / "heads" / "main").write_bytes(b"not a sha\n")
    else:
        sha = (git / "refs" / "heads" / "main").read_text(encoding="utf-8").strip()
        loose = git / "objects" / sha[:2] / sha[2:]
        loose.chmod(0o644)
        loose.write_bytes(b"garbage")
    assert commit_time(repository) is None


@pytest.mark.parametrize(
    ("text", "times"),
    [
        ("student,submitted_at\nalice,2026-03-02T01:00:00-05:00\nbob,2026-03-01T12:00:00Z\ncarol,\n",
         {"alice": datetime(2026, 3, 2, 1, tzinfo=EST), "bob": datetime(2026, 3, 1, 12, tzinfo=UTC)}),
        ("id,user_id,submitted_at,late\n9001,1105,2026-03-02T04:59:00Z,true\n9002,1106,,false\n",
         {"1105": datetime(2026, 3, 2, 4, 59, tzinfo=UTC)}),
        ("\ufeffIdentifier,Full name,Email address,Status,Last modified (submission)\r\n"
         "Participant 81000,Student Number0,s0@uni.edu,Submitted for grading,\"Monday, 2 March 2026, 11:59 PM\"\r\n"  # noqa: E501
         "Participant 81001,Student Number1,s1@uni.edu,No submission,-\r\n",
         {"81000": datetime(2026, 3, 2, 23, 59)}),
    ],
    ids=["plain-csv", "canvas-submissions-csv", "moodle-grading-worksheet"],
)  # fmt: skip
def test_times_an_instructor_gives_are_read_by_their_header(text: str, times: dict[str, datetime]) -> None:
    assert parse_submitted_at(text.encode("utf-8"), where="times.csv") == times


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("who,when\nalice,2026-03-01\n", "times.csv has no student column: expected student,submitted_at (or a Canvas submissions CSV's user_id,submitted_at, or Moodle's grading worksheet), found who,when"),  # noqa: E501
        ("student,submitted_at\nalice,=NOW()\n", "times.csv: refused:\n  line 2: '=NOW()' is not a time: write e.g. 2026-03-01T23:59:00-05:00\nCorrect these rows and run the command again."),  # noqa: E501
    ],
    ids=["no-student-column", "formula-time"],
)  # fmt: skip
def test_a_times_file_that_is_not_one_says_what_was_expected(text: str, message: str) -> None:
    with pytest.raises(LatePolicyError) as raised:
        parse_submitted_at(text.encode("utf-8"), where="times.csv")
    assert str(raised.value) == message
