"""Zips are read entry by entry into scratch, within limits; hostile entries are refused with a reason."""

from __future__ import annotations

import io
import stat
import zipfile
from pathlib import Path

import pytest

from grader.classroom.tree import Limits, read_tree


def _zip(path: Path, entries: list[tuple[str | zipfile.ZipInfo, bytes]]) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as bundle:
        for name, data in entries:
            bundle.writestr(name, data)
    return path


def _bytes(entries: list[tuple[str, bytes]]) -> bytes:
    stream = io.BytesIO()
    with zipfile.ZipFile(stream, "w", zipfile.ZIP_DEFLATED) as bundle:
        for name, data in entries:
            bundle.writestr(name, data)
    return stream.getvalue()


def _link(name: str) -> zipfile.ZipInfo:
    info = zipfile.ZipInfo(name)
    info.external_attr = (stat.S_IFLNK | 0o777) << 16
    return info


@pytest.mark.parametrize(
    ("name", "reason"),
    [
        ("../../etc/cron.d/x.py", "a name climbing out of the zip with ../ (path traversal)"),
        ("a/../../x.py", "a name climbing out of the zip with ../ (path traversal)"),
        ("/etc/passwd", "an absolute name (it would be written outside the scratch folder)"),
        ("C:\\Windows\\x.py", "an absolute name (it would be written outside the scratch folder)"),
        ("..\\..\\x.py", "a name climbing out of the zip with ../ (path traversal)"),
    ],
    ids=["dotdot", "inner-dotdot", "absolute", "drive", "backslash-dotdot"],
)
def test_entries_leaving_the_scratch_folder_are_refused(tmp_path: Path, name: str, reason: str) -> None:
    archive = _zip(tmp_path / "in" / "class.zip", [(name, b"x = 1\n"), ("ok/opengym.py", b"x = 1\n")])
    tree = read_tree(archive, tmp_path / "scratch")
    assert [(s.where, s.reason) for s in tree.refused] == [(name, reason)]
    assert [entry.relative for entry in tree.entries] == ["ok/opengym.py"]
    written = [path for path in (tmp_path / "scratch").rglob("*") if path.is_file()]
    assert all(path.is_relative_to(tmp_path / "scratch") for path in written) and len(written) == 1
    assert not (tmp_path / "etc").exists() and not (tmp_path / "x.py").exists()


def test_a_symlink_entry_is_refused(tmp_path: Path) -> None:
    archive = _zip(tmp_path / "class.zip", [(_link("alice/opengym.py"), b"/etc/passwd")])
    tree = read_tree(archive, tmp_path / "scratch")
    assert [s.reason for s in tree.refused] == ["a symbolic link stored in the zip: links are never followed"]
    assert tree.entries == []


def test_a_zip_bomb_entry_is_refused_by_its_ratio(tmp_path: Path) -> None:
    archive = _zip(tmp_path / "class.zip", [("bomb.py", b"\0" * (20 * 2**20)), ("ok.py", b"x = 1\n")])
    tree = read_tree(archive, tmp_path / "scratch")
    (refusal,) = tree.refused
    assert refusal.where == "bomb.py" and "over the 200:1 limit (a zip bomb?)" in refusal.reason
    assert [entry.relative for entry in tree.entries] == ["ok.py"]


def test_sizes_and_counts_are_bounded(tmp_path: Path) -> None:
    archive = _zip(tmp_path / "class.zip", [(f"s{n}/opengym.py", b"x = 1\n" * 10) for n in range(5)])
    tree = read_tree(archive, tmp_path / "scratch", Limits(max_files=3, max_file_bytes=1000))
    assert len(tree.entries) == 3
    assert [(s.where, s.reason) for s in tree.refused] == [
        ("class.zip", "2 entries not read: over the 3-file limit of a download")
    ]
    small = read_tree(archive, tmp_path / "scratch2", Limits(max_file_bytes=20))
    assert small.entries == [] and all("over the 20 limit" in s.reason for s in small.refused)


def test_nested_zips_are_read_to_a_depth_and_macos_forks_ignored(tmp_path: Path) -> None:
    deepest = _bytes([("opengym.py", b"x = 1\n")])
    level2 = _bytes([("inner.zip", deepest), ("__MACOSX/._inner.zip", b"\0")])
    archive = _zip(tmp_path / "class.zip", [("alice/sub.zip", level2)])
    tree = read_tree(archive, tmp_path / "scratch")
    assert [entry.relative for entry in tree.entries] == ["alice/sub.zip/inner.zip/opengym.py"]
    assert tree.ignored == 1
    shallow = read_tree(archive, tmp_path / "scratch2", Limits(max_zip_depth=2))
    assert [(s.where, s.reason) for s in shallow.refused] == [
        ("alice/sub.zip/inner.zip", "a zip nested deeper than 2 zips")
    ]


def test_a_corrupt_zip_is_refused_not_raised(tmp_path: Path) -> None:
    (tmp_path / "class").mkdir()
    (tmp_path / "class" / "alice.zip").write_bytes(b"PK\x03\x04 not really")
    tree = read_tree(tmp_path / "class", tmp_path / "scratch")
    assert [s.where for s in tree.refused] == ["alice.zip"]
    assert tree.refused[0].reason.startswith("not a readable zip (BadZipFile")


def test_entry_names_never_reach_the_file_system(tmp_path: Path) -> None:
    archive = _zip(tmp_path / "class.zip", [("alice/" + "x" * 300 + ".py", b"x = 1\n")])
    tree = read_tree(archive, tmp_path / "scratch")
    (entry,) = tree.entries
    assert entry.relative.endswith(".py") and len(entry.path.name) < 20


MIB_OF_ZEROS = b"\0" * 2**20
"""An entry of exactly 1 MiB: below the ratio check's size, so only the total budget bounds many of them."""


def _scratch_bytes(scratch: Path) -> int:
    return sum(path.stat().st_size for path in scratch.rglob("*") if path.is_file())


def test_every_download_of_a_command_shares_one_budget(tmp_path: Path) -> None:
    # Hostile (scaled down from 1,100 entries of 1 MiB against 1 GiB): each zip fits the budget alone,
    # together they do not, so the command writes no more than the budget in all.
    from grader.classroom.discovery import read_all

    zips = [
        _zip(
            tmp_path / "in" / f"part{number}.zip",
            [(f"s{number}{k}/x{k}.bin", MIB_OF_ZEROS) for k in range(3)],
        )
        for number in range(2)
    ]
    limits = Limits(max_total_bytes=4 * 2**20)
    reads = read_all(zips, scratch=tmp_path / "scratch", limits=limits)
    refused = [skipped for read in reads for skipped in read.tree.refused]
    assert [skipped.reason for skipped in refused] == [
        f"the download's zips expand past {4 * 2**20:,} bytes"
    ] * 2
    assert sum(len(read.tree.entries) for read in reads) == 4
    assert _scratch_bytes(tmp_path / "scratch") == 4 * 2**20
