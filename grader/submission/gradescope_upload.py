"""An upload on Gradescope: its identity (``submission_metadata.json``) and the grading seed derived from it.

Each upload is graded on its own seed, `grader.seeds.upload_seed` of the bundle's secret and the upload's
identity, so that what one upload learns of its starts says nothing about another's (docs/gradescope.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from grader.errors import GradescopeError
from grader.seeds import held_out_seed, upload_seed
from grader.submission.untrusted_file import UnsafeFile, read_untrusted

METADATA_FILE = "submission_metadata.json"
"""Gradescope's description of the upload being graded, in the autograder's root."""
METADATA_LIMIT_BYTES = 64 * 2**20
"""Read no more of the metadata (it embeds every earlier upload's results.json)."""
SECRET_LIMIT_BYTES = 4096
"""A bundle's secret is 64 hex digits and a newline."""


class GradescopeUser(BaseModel):
    """A submitter in Gradescope's ``submission_metadata.json``."""

    model_config = ConfigDict(extra="ignore")

    id: int | str


class SubmissionMetadata(BaseModel):
    """What gymgrade reads of ``/autograder/submission_metadata.json``: the upload's identity.

    See https://gradescope-autograders.readthedocs.io/en/latest/submission_metadata/ (the file also holds
    the assignment and every earlier upload with its results, which gymgrade ignores).
    """

    model_config = ConfigDict(extra="ignore")

    id: int | str = Field(description="Gradescope's unique id of this upload.")
    created_at: str = Field(description="When it was uploaded (ISO 8601, as Gradescope writes it).")
    users: list[GradescopeUser] = Field(description="Who submitted it (several for a group).")

    def identity(self) -> tuple[str, ...]:
        """The upload's identity as the seed derivation reads it (users in a fixed order)."""
        users = sorted(str(user.id) for user in self.users)
        return ("gradescope", str(self.id), self.created_at, *users)


@dataclass(frozen=True)
class UploadSeed:
    """The grading seed of one upload and where it came from (kept in the results for the instructor).

    Attributes:
        seed: The grading seed.
        source: ``derived`` (from the bundle's secret and the upload's metadata: reproducible with
            ``gymgrade gradescope-seed``), ``given`` (``--seed``) or ``fresh`` (drawn at random because the
            metadata could not be read: regrade with ``--seed``).
        identity: The upload's identity it was derived from (empty unless derived).
        note: Why a fresh seed was drawn; empty otherwise.
    """

    seed: int
    source: Literal["derived", "given", "fresh"]
    identity: tuple[str, ...] = ()
    note: str = ""

    def describe(self) -> str:
        """The instructor's note: the seed, its origin and how to regrade the upload identically."""
        if self.source == "derived":
            return (
                f"Grading seed {self.seed}, derived from the bundle's secret and this upload ({', '.join(self.identity)}). "  # noqa: E501
                "Regrade it identically with: gymgrade gradescope-seed --bundle autograder.zip --metadata submission_metadata.json --submission FILE"  # noqa: E501
            )
        origin = "given with --seed" if self.source == "given" else f"drawn at random ({self.note})"
        return f"Grading seed {self.seed}, {origin}. Regrade it identically with: gymgrade check FILE --seed {self.seed}"  # noqa: E501


def read_metadata(path: Path) -> SubmissionMetadata:
    """Gradescope's metadata of the upload, read within `METADATA_LIMIT_BYTES`.

    Raises:
        GradescopeError: It is missing, too large, not JSON, or lacks the upload's id, time or users.
    """
    try:
        with path.open("rb") as handle:
            data = handle.read(METADATA_LIMIT_BYTES + 1)
    except OSError as error:
        raise GradescopeError(f"cannot read {path}: {error.strerror or error}") from error
    if len(data) > METADATA_LIMIT_BYTES:
        raise GradescopeError(
            f"{path} is larger than {METADATA_LIMIT_BYTES:,} bytes; expected Gradescope's metadata"
        )
    try:
        return SubmissionMetadata.model_validate_json(data)
    except ValidationError as error:
        first = error.errors()[0]
        where = ".".join(str(part) for part in first["loc"]) or "the file"
        raise GradescopeError(
            f"{path} is not Gradescope's submission metadata: {where}: {first['msg']}; "
            "expected JSON with the upload's id, created_at and users"
        ) from error


def seed_for_upload(root: Path, *, secret_file: Path) -> UploadSeed:
    """The grading seed of the upload in ``root``: derived from the bundle's secret and its metadata.

    Never raises: where the secret or the metadata cannot be read, a fresh seed is drawn at random (so the
    upload still gets starts nobody could know, and results.json is still written) and the reason is
    recorded for the instructor.
    """
    try:
        secret = read_secret(secret_file)
        identity = read_metadata(root / METADATA_FILE).identity()
        return UploadSeed(upload_seed(secret, identity), "derived", identity)
    except (GradescopeError, OSError, UnicodeDecodeError, ValueError) as error:
        return UploadSeed(held_out_seed(), "fresh", note=str(error))


def read_secret(path: Path) -> str:
    """The bundle's seed secret, read before any file of the upload is touched, and left readable by its
    owner alone (student code runs as another uid, and bubblewrap and Landlock do not show the file).

    Raises:
        GradescopeError: The secret is a link, not a regular file, too large or unreadable.
    """
    try:
        data = read_untrusted(path, limit=SECRET_LIMIT_BYTES, one_name=False)
    except UnsafeFile as error:
        raise GradescopeError(f"the bundle's seed secret cannot be used: {error}") from error
    if len(data) > SECRET_LIMIT_BYTES:
        raise GradescopeError(
            f"{path} is larger than {SECRET_LIMIT_BYTES:,} bytes; expected the bundle's secret"
        )
    if path.stat().st_mode & 0o077:
        path.chmod(0o600)
    return data.decode("ascii")
