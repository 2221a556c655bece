"""Every layout's realistic download is recognised and grouped: a submission per student under their
identity, the right graded file, lateness, groups, refusals and unattributed files."""

from __future__ import annotations

from pathlib import Path

import pytest

from grader.classroom import GradedFileRule, discover

from .downloads import BUILDERS, DUE, Expected

RULE = GradedFileRule(functions=("random_blackjack", "blackjack", "cartpole", "car", "taxi", "find_qvalues"))


def _discover(expected: Expected, tmp_path: Path, layout: str | None = None):  # type: ignore[no-untyped-def]
    return discover(expected.path, layout=layout, rule=RULE, scratch=tmp_path / "scratch", due=DUE)


@pytest.mark.parametrize("layout", list(BUILDERS), ids=list(BUILDERS))
def test_each_layout_is_recognised_and_grouped_by_student(layout: str, tmp_path: Path) -> None:
    expected = BUILDERS[layout](tmp_path / "download", 4)
    download = _discover(expected, tmp_path)
    assert download.layout == expected.layout
    graded = {
        submission.identity: submission.graded_file.relative if submission.graded_file else None
        for submission in download.submissions
    }
    assert graded == expected.graded
    assert {submission.identity for submission in download.submissions if submission.late} == expected.late
    for identity, members in expected.groups.items():
        (group,) = [submission for submission in download.submissions if submission.identity == identity]
        assert tuple(member.identity for member in group.members) == members
    for identity, name in expected.names.items():
        (submission,) = [submission for submission in download.submissions if submission.identity == identity]
        assert submission.members[0].name == name
    refused = [skipped.where for skipped in download.refused]
    for where in expected.refused:
        assert any(where in found for found in refused), (where, download.refused)
    assert [skipped.where for skipped in download.unattributed] == expected.unattributed
    for submission in download.submissions:
        assert submission.why, submission


@pytest.mark.parametrize("layout", list(BUILDERS), ids=list(BUILDERS))
def test_naming_the_layout_gives_the_same_submissions(layout: str, tmp_path: Path) -> None:
    expected = BUILDERS[layout](tmp_path / "download", 3)
    named = _discover(expected, tmp_path / "a", layout=expected.layout)
    recognised = _discover(expected, tmp_path / "b")
    assert [s.identity for s in named.submissions] == [s.identity for s in recognised.submissions]


def test_graded_file_choices_say_why(tmp_path: Path) -> None:
    expected = BUILDERS["plain"](tmp_path / "download", 1)
    download = _discover(expected, tmp_path)
    why = {submission.identity: submission.why for submission in download.submissions}
    assert why["bob"] == "named opengym.py, the lab's file name"
    assert why["carol"] == "the only .py/.ipynb file (nothing else)"
    assert why["dan"] == "defines 6 of the lab's 6 functions, more than helpers.py"
    assert why["eve"] == (
        "no .py or .ipynb file to grade (test files and checkpoints are never graded); "
        "refused eve/opengym.py: a symbolic link (to /etc/passwd): links are never followed"
    )


def test_a_symlink_is_refused_with_its_target_and_never_read(tmp_path: Path) -> None:
    expected = BUILDERS["plain"](tmp_path / "download", 1)
    download = _discover(expected, tmp_path)
    assert [(s.where, s.reason) for s in download.refused] == [
        ("eve/opengym.py", "a symbolic link (to /etc/passwd): links are never followed")
    ]
    every_file = [file.path for submission in download.submissions for file in submission.files]
    assert all(not path.is_symlink() for path in every_file)


def test_a_hard_link_and_a_fifo_are_refused(tmp_path: Path) -> None:
    folder = tmp_path / "class"
    (folder / "ann").mkdir(parents=True)
    (folder / "ann" / "opengym.py").write_text("x = 1\n")
    outside = tmp_path / "secret.py"
    outside.write_text("token = 1\n")
    (folder / "ben").mkdir()
    (folder / "ben" / "opengym.py").hardlink_to(outside)
    (folder / "ben" / "notes.txt").write_text("mine\n")
    import os

    os.mkfifo(folder / "ann" / "pipe.py")
    download = discover(folder, rule=RULE)
    reasons = {s.where: s.reason for s in download.refused}
    assert reasons["ben/opengym.py"].startswith("a hard link (2 names for one file")
    assert reasons["ann/pipe.py"] == "not a regular file (a device, FIFO or socket)"
    graded = {s.identity: s.graded_file for s in download.submissions}
    assert graded["ben"] is None and graded["ann"] is not None


def test_a_zip_needs_a_scratch_folder(tmp_path: Path) -> None:
    expected = BUILDERS["canvas"](tmp_path / "download", 1)
    download = discover(expected.path, rule=RULE)
    assert download.submissions == []
    assert [s.reason for s in download.refused] == ["a zip needs a scratch folder to be read into"]


def test_an_unknown_layout_is_named_with_the_known_ones(tmp_path: Path) -> None:
    from grader.classroom.errors import UnknownLayout

    with pytest.raises(
        UnknownLayout, match=r"unknown layout 'brightspace': use one of plain, canvas, gradescope"
    ):
        discover(tmp_path, layout="brightspace")


def test_a_named_layout_that_does_not_fit_says_so(tmp_path: Path) -> None:
    from grader.classroom.errors import LayoutMismatch

    expected = BUILDERS["plain"](tmp_path / "download", 2)
    with pytest.raises(LayoutMismatch, match="does not look like a Moodle Download all submissions download"):
        discover(expected.path, layout="moodle")


def test_a_student_whose_every_file_is_refused_gets_a_submission_saying_so(tmp_path: Path) -> None:
    folder = tmp_path / "moodle"
    (folder / "Ann Lee_501_assignsubmission_file_").mkdir(parents=True)
    (folder / "Ann Lee_501_assignsubmission_file_" / "opengym.py").write_text("x = 1\n")
    (folder / "Eve Ray_502_assignsubmission_file_").mkdir()
    (folder / "Eve Ray_502_assignsubmission_file_" / "opengym.py").symlink_to(folder.parent)
    download = discover(folder, rule=RULE)
    eve = download.submissions[1]
    assert (eve.identity, eve.display_name, eve.graded_file, eve.files) == ("502", "Eve Ray (502)", None, ())
    assert eve.why == (
        "nothing to grade: every file was refused (Eve Ray_502_assignsubmission_file_/opengym.py: "
        f"a symbolic link (to {folder.parent}): links are never followed)"
    )


def test_several_downloads_are_read_apart_and_a_student_twice_is_refused(tmp_path: Path) -> None:
    from grader.classroom import discover_all

    first = BUILDERS["canvas"](tmp_path / "one", 2)
    second = BUILDERS["canvas"](tmp_path / "two", 3)
    download = discover_all([first.path, second.path], rule=RULE, scratch=tmp_path / "scratch", due=DUE)
    assert download.layout == "canvas"
    assert {s.identity for s in download.submissions} == set(first.graded) | set(second.graded)
    twice = [s.where for s in download.refused if s.reason.startswith("a second submission for 1000 ")]
    assert twice == ["student0_1000_5001_opengym.py"]
    paths = [file.path for submission in download.submissions for file in submission.files]
    assert len(set(paths)) == len(paths), "each zip keeps its own scratch files"


def _zip_of(path: Path, entries: dict[str, bytes]) -> Path:
    import zipfile

    with zipfile.ZipFile(path, "w") as bundle:
        for name, data in entries.items():
            bundle.writestr(name, data)
    return path


ESCAPING = {"../x.py": b"x = 1\n", "/tmp/x.py": b"x = 1\n", "C:/x.py": b"x = 1\n", "..\\y.py": b"y = 1\n"}


@pytest.mark.parametrize("wrapped", [False, True], ids=["class-zip", "class-folder-holding-the-zip"])
def test_refused_entry_names_never_become_students(tmp_path: Path, wrapped: bool) -> None:
    """Hostile: entries named ``../x``, ``/tmp/x`` and ``C:/x`` are refused, listed, and nobody's row."""
    entries = {"alice/opengym.py": b"def blackjack(n):\n    return 0\n", **ESCAPING}
    if wrapped:
        folder = tmp_path / "class"
        folder.mkdir()
        (folder / "bob").mkdir()
        (folder / "bob" / "opengym.py").write_text("def blackjack(n):\n    return 1\n")
        _zip_of(folder / "bob" / "extra.zip", ESCAPING)
        target = folder
    else:
        target = _zip_of(tmp_path / "class.zip", entries)
    download = discover(target, rule=RULE, scratch=tmp_path / "scratch")
    expected = ["bob"] if wrapped else ["alice"]
    assert [submission.identity for submission in download.submissions] == expected
    assert len(download.refused) == len(ESCAPING)
    if wrapped:  # bob's own zip: its refused entries are his, named in his row
        (bob,) = download.submissions
        assert len(bob.refused) == len(ESCAPING)
        assert "refused bob/extra.zip/../x.py: a name climbing out of the zip" in bob.why


def test_a_submissions_why_names_a_few_refused_files_and_counts_the_rest(tmp_path: Path) -> None:
    """Hostile: 2,000 link entries in one student's zip make a bounded reason, listed in linear time."""
    import zipfile

    folder = tmp_path / "class"
    (folder / "mallory").mkdir(parents=True)
    (folder / "mallory" / "opengym.py").write_text("def blackjack(n):\n    return 0\n")
    with zipfile.ZipFile(folder / "mallory" / "links.zip", "w") as bundle:
        for number in range(2_000):
            link = zipfile.ZipInfo(f"l{number}.py")
            link.external_attr = 0o120777 << 16
            bundle.writestr(link, "/etc/passwd")
    download = discover(folder, rule=RULE, scratch=tmp_path / "scratch")
    (mallory,) = download.submissions
    assert len(mallory.refused) == 2_000
    assert mallory.why.endswith("; and 1,995 more")
    assert len(mallory.why) < 1_000


LAB = b"import gym\n\ndef random_blackjack(n):\n    return 0.0\n"


def _plain(root: Path, files: list[str]) -> Path:
    for relative in files:
        (root / relative).parent.mkdir(parents=True, exist_ok=True)
        (root / relative).write_bytes(LAB)
    return root


def _graded_files(root: Path, **options: object) -> dict[str, str | None]:
    download = discover(root, rule=RULE, **options)  # type: ignore[arg-type]
    assert download.layout == "plain"
    return {s.identity: s.graded_file.relative if s.graded_file else None for s in download.submissions}


@pytest.mark.parametrize(
    ("files", "graded"),
    [
        (
            ["alice/opengym.ipynb", "bob/opengym.py", "mallory/alice/opengym.py", "mallory/x1/helper.py"],
            {"alice": "alice/opengym.ipynb", "bob": "bob/opengym.py", "mallory": "mallory/alice/opengym.py"},
        ),
        (
            [
                "sec1/alice/opengym.py",
                "sec1/mallory/bob/opengym.py",
                "sec1/mallory/x1/helper.py",
                "sec2/bob/opengym.py",
                "sec2/carol/opengym.py",
            ],
            {
                "alice": "sec1/alice/opengym.py",
                "bob": "sec2/bob/opengym.py",
                "carol": "sec2/carol/opengym.py",
                "mallory": "sec1/mallory/bob/opengym.py",
            },
        ),
        (
            ["alice/lab/opengym.py", "bob/mallory/opengym.py", "bob/x1/helper.py", "carol/src/opengym.py"],
            {
                "alice": "alice/lab/opengym.py",
                "bob": "bob/mallory/opengym.py",
                "carol": "carol/src/opengym.py",
            },
        ),
    ],
    ids=["a-folder-holding-only-folders-is-a-student", "inside-sections", "when-every-student-nests"],
)
def test_a_students_own_subfolders_are_their_files_and_claim_nobody(
    tmp_path: Path, files: list[str], graded: dict[str, str]
) -> None:
    # Hostile: mallory/alice/opengym.py must not be graded as alice's (outranking her notebook), nor
    # mallory/x1/ become a student; sections are decided from the whole download, not one student's folder.
    assert _graded_files(_plain(tmp_path / "class", files)) == graded


@pytest.mark.parametrize(
    ("files", "graded"),
    [
        (
            ["sec1/alice/opengym.py", "sec1/bob/opengym.py", "sec2/carol/opengym.py", "sec2/dave/opengym.py"],
            {
                "alice": "sec1/alice/opengym.py",
                "bob": "sec1/bob/opengym.py",
                "carol": "sec2/carol/opengym.py",
                "dave": "sec2/dave/opengym.py",
            },
        ),
        (
            [
                "fall/sec1/alice/opengym.py",
                "fall/sec1/bob/opengym.py",
                "fall/sec2/carol/opengym.py",
                "fall/sec2/dave/opengym.py",
            ],
            {
                "alice": "fall/sec1/alice/opengym.py",
                "bob": "fall/sec1/bob/opengym.py",
                "carol": "fall/sec2/carol/opengym.py",
                "dave": "fall/sec2/dave/opengym.py",
            },
        ),
        (
            ["0042.py", "alice/opengym.py", "alice/old/opengym.py", "notes.txt"],
            {"0042": "0042.py", "alice": "alice/opengym.py"},
        ),
    ],
    ids=["sections", "a-folder-wrapping-sections", "files-and-folders"],
)
def test_honest_sections_are_recognised_from_the_downloads_shape(
    tmp_path: Path, files: list[str], graded: dict[str, str]
) -> None:
    assert _graded_files(_plain(tmp_path / "class", files)) == graded


def test_sections_can_be_named_outright(tmp_path: Path) -> None:
    root = _plain(tmp_path / "class", ["sec1/alice/opengym.py", "sec2/bob/opengym.py"])
    assert _graded_files(root) == {"sec1": "sec1/alice/opengym.py", "sec2": "sec2/bob/opengym.py"}
    assert _graded_files(root, sections=1) == {"alice": "sec1/alice/opengym.py", "bob": "sec2/bob/opengym.py"}
    flat = _plain(tmp_path / "flat", ["sec1/alice/opengym.py", "sec1/bob/opengym.py"])
    assert _graded_files(flat, sections=0) == {"sec1": None}, "two lab files at one depth: nothing guessed"


def test_sections_with_another_layout_are_refused(tmp_path: Path) -> None:
    from grader.classroom.errors import LayoutMismatch

    with pytest.raises(LayoutMismatch, match="--sections 1 describes plain folders, but --layout canvas"):
        discover(tmp_path, layout="canvas", sections=1)


@pytest.mark.parametrize(
    ("value", "message"),
    [("-1", "expected 0 to 32 levels of section folders, found -1"), ("two", "found 'two'")],
    ids=["negative", "not-a-number"],
)
def test_the_sections_option_says_what_it_expects(
    value: str, message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    from grader import cli

    assert cli.build_parser().parse_args(["grade", "x", "--out", "o", "--sections", "1"]).sections == 1
    with pytest.raises(SystemExit):
        cli.build_parser().parse_args(["grade", "x", "--out", "o", "--sections", value])
    assert message in capsys.readouterr().err
