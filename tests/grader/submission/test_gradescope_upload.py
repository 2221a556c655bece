"""An upload's identity from Gradescope's metadata, and its seed from it and the bundle's secret."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from gradescope_support import SECRET, metadata

from grader.cli.gradescope import SECRET_FILE
from grader.seeds import upload_seed
from grader.submission.gradescope_upload import METADATA_FILE, read_metadata, seed_for_upload


def test_an_uploads_identity_is_read_from_gradescopes_metadata(tmp_path: Path) -> None:
    path = tmp_path / METADATA_FILE
    path.write_text(json.dumps(metadata(123456, "2026-11-25T10:00:00.000000-08:00", 9, 4)))
    assert read_metadata(path).identity() == (
        "gradescope",
        "123456",
        "2026-11-25T10:00:00.000000-08:00",
        "4",
        "9",
    )
    (tmp_path / SECRET_FILE).write_text(SECRET + "\n")
    upload = seed_for_upload(tmp_path, secret_file=tmp_path / SECRET_FILE)
    assert (upload.seed, upload.source) == (upload_seed(SECRET, read_metadata(path).identity()), "derived")


@pytest.mark.parametrize(
    ("content", "secret", "note"),
    [
        (None, SECRET, "cannot read"),
        ("{not json", SECRET, "is not Gradescope's submission metadata: the file: Invalid JSON"),
        (
            '{"id": 5, "users": []}',
            SECRET,
            "is not Gradescope's submission metadata: created_at: Field required",
        ),
        (json.dumps(metadata(7, "2026-11-25T10:00:00-08:00", 5)), None, "No such file or directory"),
        (
            json.dumps(metadata(7, "2026-11-25T10:00:00-08:00", 5)),
            "abc",
            "a seed secret must be at least 64 hex",
        ),
    ],
    ids=["no-metadata", "not-json", "no-time", "no-secret", "short-secret"],
)
def test_an_unreadable_secret_or_metadata_gets_a_fresh_seed_and_says_why(
    tmp_path: Path, content: str | None, secret: str | None, note: str
) -> None:
    if content is not None:
        (tmp_path / METADATA_FILE).write_text(content)
    if secret is not None:
        (tmp_path / SECRET_FILE).write_text(secret + "\n")
    seeds = {seed_for_upload(tmp_path, secret_file=tmp_path / SECRET_FILE) for _ in range(3)}
    assert len({upload.seed for upload in seeds}) == 3, "never a fixed fallback seed"
    for upload in seeds:
        assert upload.source == "fresh" and note in upload.note, upload.note
        assert upload.describe().endswith(
            f"Regrade it identically with: gymgrade check FILE --seed {upload.seed}"
        )
