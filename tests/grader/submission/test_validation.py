"""Tests of grader/submission/validation.py: every way a file can be ungradable gets a clear verdict."""

from __future__ import annotations

import pytest

from grader.submission.validation import check_source

CASES = [
    (b"", "missing", "opengym.py is empty: nothing to grade."),
    (b"\n   \n\t", "missing", "opengym.py is empty: nothing to grade."),
    (
        b"\x89PNG\r\n\x1a\n\x00\x00",
        "error",
        "opengym.py is not a text file (it contains a NUL byte at offset 8)",
    ),
    (b"# caf\xe9\nx = 1\n", "error", "opengym.py is not UTF-8 text: byte 0xe9 on line 1 cannot be decoded."),
    (b"x = 1\ny = '\xff'\n", "error", "opengym.py is not UTF-8 text: byte 0xff on line 2"),
    (
        b"def cartpole(:\n    pass\n",
        "error",
        "opengym.py is not valid Python: invalid syntax (line 1, column 14).",
    ),
    (b"def car():\nreturn 1\n", "error", "opengym.py is not valid Python: expected an indented block"),
    (
        b"x = 1" * 300_000,
        "error",
        "opengym.py is 1,500,000 bytes; a submission may be at most 1,000,000 bytes.",
    ),
]


@pytest.mark.parametrize(
    ("data", "status", "message"),
    CASES,
    ids=["empty", "whitespace", "binary", "latin-1", "bad-byte-line-2", "syntax", "indentation", "too-large"],
)
def test_ungradable_files_get_a_clear_verdict(data: bytes, status: str, message: str) -> None:
    verdict = check_source(data, "opengym.py")
    assert verdict is not None
    assert verdict.status == status
    assert verdict.message.startswith(message)


@pytest.mark.parametrize(
    "data",
    [b"def car():\n    return 1\n", "# coding: utf-8\nname = 'José'\n".encode(), b"\xef\xbb\xbfx = 1\n"],
    ids=["plain", "non-ascii-utf8", "utf8-bom"],
)
def test_python_sources_pass(data: bytes) -> None:
    assert check_source(data, "opengym.py") is None


def test_compiling_never_executes() -> None:
    data = b"import os\nos.remove('/definitely/not/here')\nraise SystemExit(3)\n"
    assert check_source(data, "opengym.py") is None
