"""Tests of grader/submission/untrusted_file.py: a submitted file is read once, from a descriptor, never
through a link.

Each hostile sample points at a "secret" outside the upload (as the Gradescope bundle's seed secret is);
none of its bytes may come back.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import pytest

from grader.submission.untrusted_file import UnsafeFile, read_untrusted

SECRET = b"c0ffee" * 10 + b"\n"


def _symlink(upload: Path, secret: Path) -> Path:
    (upload / "opengym.py").symlink_to(secret)
    return upload / "opengym.py"


def _relative_symlink(upload: Path, secret: Path) -> Path:
    (upload / "opengym.py").symlink_to(os.path.relpath(secret, upload))
    return upload / "opengym.py"


def _hard_link(upload: Path, secret: Path) -> Path:
    os.link(secret, upload / "opengym.py")
    return upload / "opengym.py"


def _folder_link(upload: Path, secret: Path) -> Path:
    (upload / "lab").symlink_to(secret.parent, target_is_directory=True)
    return upload / "lab" / secret.name


def _fifo(upload: Path, secret: Path) -> Path:
    os.mkfifo(upload / "opengym.py")
    return upload / "opengym.py"


def _folder(upload: Path, secret: Path) -> Path:
    (upload / "opengym.py").mkdir()
    return upload / "opengym.py"


HOSTILE: list[tuple[str, Callable[[Path, Path], Path], str]] = [
    ("symlink", _symlink, "opengym.py is a symbolic link (to {secret}): links are never followed, so it was not read. Submit the file itself, not a link to it."),  # noqa: E501
    ("relative-symlink", _relative_symlink, "opengym.py is a symbolic link (to ../source/seed_secret): links are never followed"),  # noqa: E501
    ("hard-link", _hard_link, "opengym.py is a hard link (2 names for one file, possibly outside the submission): it was not read. Submit a copy of the file itself."),  # noqa: E501
    ("folder-link", _folder_link, "lab is a symbolic link (to {folder}): links are never followed"),
    ("fifo", _fifo, "opengym.py is not a regular file (a folder, device, FIFO or socket): it was not read."),
    ("folder", _folder, "opengym.py is not a regular file"),
]  # fmt: skip


@pytest.fixture
def layout(tmp_path: Path) -> tuple[Path, Path]:
    """An upload folder and, beside it, a secret only the grader may read."""
    (tmp_path / "source").mkdir()
    secret = tmp_path / "source" / "seed_secret"
    secret.write_bytes(SECRET)
    secret.chmod(0o600)
    (tmp_path / "submission").mkdir()
    return tmp_path / "submission", secret


@pytest.mark.parametrize(
    ("make", "message"), [case[1:] for case in HOSTILE], ids=[case[0] for case in HOSTILE]
)
@pytest.mark.parametrize("rooted", [True, False], ids=["below-root", "single-file"])
def test_a_link_or_special_file_is_refused_and_nothing_of_its_target_read(
    layout: tuple[Path, Path], make: Callable[[Path, Path], Path], message: str, rooted: bool
) -> None:
    upload, secret = layout
    path = make(upload, secret)
    expected = message.format(secret=secret, folder=secret.parent)
    if not rooted and path.parent != upload:
        # A single file's folders are its user's own choice (gymgrade check FILE): only its name counts.
        assert read_untrusted(path, limit=100) == SECRET
        return
    with pytest.raises(UnsafeFile) as refused:
        read_untrusted(path, limit=100, root=upload if rooted else None)
    assert str(refused.value).startswith(expected)
    assert SECRET.decode().strip() not in str(refused.value)


@pytest.mark.parametrize("rooted", [True, False], ids=["below-root", "single-file"])
def test_an_honest_file_is_read_up_to_one_byte_past_the_limit(tmp_path: Path, rooted: bool) -> None:
    (tmp_path / "lab").mkdir()
    path = tmp_path / "lab" / "opengym.py"
    path.write_bytes(b"x = 1\n" * 100)
    assert read_untrusted(path, limit=1000, root=tmp_path if rooted else None) == b"x = 1\n" * 100
    assert read_untrusted(path, limit=10, root=tmp_path if rooted else None) == b"x = 1\nx = 1"


def test_a_missing_file_says_so(tmp_path: Path) -> None:
    with pytest.raises(
        UnsafeFile, match=r"^gone.py could not be read \(No such file or directory\): check that"
    ):
        read_untrusted(tmp_path / "gone.py", limit=10)
