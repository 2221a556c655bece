"""The upload rules the schema states are the rules check_upload applies."""

from __future__ import annotations

import re

import pytest

from api.errors import InvalidUpload, UploadTooLarge
from api.uploads import MAX_DISPLAY_NAME_CHARS, check_upload, grading_file_name, upload_rules

MAX_BYTES = 64


def _service_accepts(name: str, content: bytes) -> bool:
    try:
        check_upload(name, content, max_bytes=MAX_BYTES)
    except (InvalidUpload, UploadTooLarge):
        return False
    return True


@pytest.mark.parametrize(
    "text",
    ["x = 1\n", "", " \n\t\r\x0b\x0c", "\x00", "x\x00", "\u00a0", "é" * MAX_BYTES, "x" * MAX_BYTES, "x" * 65],
    ids=["source", "empty", "blank", "nul", "nul-inside", "nbsp", "non-ascii-at-limit", "at-limit", "over"],
)
def test_the_content_rules_match_check_upload(text: str) -> None:
    content_schema, _ = upload_rules(MAX_BYTES)
    in_schema = (
        content_schema["minLength"] <= len(text) <= content_schema["maxLength"]
        and re.fullmatch(content_schema["pattern"], text) is not None
    )
    accepted = _service_accepts("opengym.py", text.encode("utf-8"))
    # maxLength counts characters and the limit bytes: only non-ASCII text near the limit differs.
    assert in_schema == accepted or (in_schema and len(text.encode("utf-8")) > MAX_BYTES)


@pytest.mark.parametrize(
    "name",
    [
        "opengym.py",
        "OPENGYM.PY",
        "a .py",
        "dir/x.py",
        "C:\\\\dir\\\\x.py",
        ".py",
        "..py",
        "x/.py",
        "x.pyc",
        "x",
    ],
)
def test_the_file_name_rule_matches_check_upload(name: str) -> None:
    _, encoding = upload_rules(MAX_BYTES)
    disposition = encoding["headers"]["Content-Disposition"]
    header = f'form-data; name="file"; filename="{name}"'
    assert (re.search(disposition["schema"]["pattern"], header) is not None) == _service_accepts(name, b"x=1")
    assert re.search(disposition["schema"]["pattern"], disposition["example"]) is not None


@pytest.mark.parametrize(
    ("name", "graded_as"),
    [
        ("opengym.py", "opengym.py"),
        ("opengym.ipynb", "opengym.ipynb"),
        ("my lab.py", "submission.py"),
        ("my lab.ipynb", "submission.ipynb"),
        ("policy_iteration-1.py", "submission.py"),
        ("6.py", "submission.py"),
        ("../../evil.py", "submission.py"),
        ("evil", "submission.py"),
        ("a" * (MAX_DISPLAY_NAME_CHARS - 3) + ".py", "a" * (MAX_DISPLAY_NAME_CHARS - 3) + ".py"),
        ("a" * MAX_DISPLAY_NAME_CHARS + ".py", "submission.py"),
        ("a" * 5_000 + ".ipynb", "submission.ipynb"),
    ],
    ids=[
        "module-name",
        "notebook",
        "space",
        "notebook-with-space",
        "hyphen",
        "digit-start",
        "climbing",
        "no-suffix",
        "at-the-bound",
        "over-the-bound",
        "far-over-the-bound",
    ],
)
def test_a_file_is_graded_under_its_name_only_when_that_is_a_short_module_name(
    name: str, graded_as: str
) -> None:
    """A worker's request is untrusted: whatever name it carries, the grading file's name is one safe path
    component (the name messages show is given to the grader apart, ``ClaimedJob.shown_name``)."""
    assert grading_file_name(name) == graded_as
