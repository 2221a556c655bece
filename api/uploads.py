"""Checks an uploaded file before it is queued, and turns its client-chosen name into a safe display name."""

from __future__ import annotations

import hashlib
import re
import unicodedata
from dataclasses import dataclass
from typing import Any

from api.errors import InvalidUpload, UploadTooLarge
from grader.submission.notebook import NOTEBOOK_SUFFIX

MAX_DISPLAY_NAME_CHARS = 100
_UNSAFE_NAME_CHARACTERS = re.compile(r"[^A-Za-z0-9._ -]+")
_MODULE_STEM = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
GRADING_FALLBACK_NAME = "submission.py"
# The rules of check_upload as a JSON Schema for the file's text (UTF-8): no NUL, not only whitespace
# (bytes.strip() strips exactly these six ASCII characters), and for its multipart Content-Disposition.
SOURCE_TEXT_PATTERN = r"^[^\u0000]*[^\u0000\t\n\u000b\u000c\r ][^\u0000]*$"
CONTENT_DISPOSITION_PATTERN = (
    r'filename="(?:[^"]*[/\\])?[^"/\\]*[^"/\\. ][^"/\\]*\.(?:[Pp][Yy]|[Ii][Pp][Yy][Nn][Bb])"'
)
ACCEPTED_CONTENT_TYPES = (
    "text/x-python",
    "text/plain",
    "application/octet-stream",
    "application/x-ipynb+json",
    "application/json",
)
SUBMISSION_SUFFIXES = (".py", NOTEBOOK_SUFFIX)
"""What may be uploaded: a Python source, or a Jupyter notebook whose code cells the grader extracts."""


@dataclass(frozen=True)
class CheckedUpload:
    """An upload that may be graded: its bytes, their SHA-256 and a display name that is safe anywhere."""

    display_name: str
    content: bytes
    sha256: str


def upload_rules(max_bytes: int) -> tuple[dict[str, Any], dict[str, Any]]:
    """What :func:`check_upload` accepts, for the OpenAPI schema of a multipart ``file`` part.

    Args:
        max_bytes: GYMGRADE_MAX_UPLOAD_BYTES.

    Returns:
        The JSON Schema of the part's content and its OpenAPI Encoding Object (accepted part types and
        the file-name rule, as a Content-Disposition header).
    """
    content = {
        "type": "string",
        "contentMediaType": "application/octet-stream",
        "minLength": 1,
        "maxLength": max_bytes,
        "pattern": SOURCE_TEXT_PATTERN,
        "description": (
            f"The student's opengym.py (Python source) or opengym.ipynb (a Jupyter notebook), UTF-8, at most {max_bytes} bytes (maxLength counts characters; each non-ASCII character takes 2 to 4 of the bytes), without NUL bytes, not empty or blank. "  # noqa: E501
            "Syntax errors are accepted: the grader reports them."
        ),
    }
    encoding = {
        "contentType": ", ".join(ACCEPTED_CONTENT_TYPES),
        "headers": {
            "Content-Disposition": {
                "description": (
                    "The part's file name must end in .py or .ipynb (like opengym.py); "
                    "only its last path component is kept, as a sanitised display name."
                ),
                "required": True,
                "schema": {"type": "string", "pattern": CONTENT_DISPOSITION_PATTERN},
                "example": 'form-data; name="file"; filename="opengym.py"',
            }
        },
    }
    return content, encoding


def display_name(client_name: str | None) -> str:
    """Reduce a client-supplied file name to a short, printable name (never used as a path).

    Args:
        client_name: The name the client sent, possibly with directories, control characters or worse.

    Returns:
        The last path component with every character outside ``[A-Za-z0-9._ -]`` replaced by ``_``,
        no leading dots or spaces, at most 100 characters.
    """
    name = (client_name or "").replace("\\", "/").rsplit("/", 1)[-1]
    name = unicodedata.normalize("NFKC", name)
    name = _UNSAFE_NAME_CHARACTERS.sub("_", name).lstrip(". ").strip()
    if len(name) <= MAX_DISPLAY_NAME_CHARS:
        return name
    suffix = _suffix(name)
    return name[: MAX_DISPLAY_NAME_CHARS - len(suffix)] + suffix


def _suffix(name: str) -> str:
    return next((suffix for suffix in SUBMISSION_SUFFIXES if name.lower().endswith(suffix)), "")


def grading_file_name(name: str) -> str:
    """The file name a submission is graded under: its display name when it is a valid module name of at
    most ``MAX_DISPLAY_NAME_CHARS`` characters, else ``submission`` with its suffix (``.py`` or ``.ipynb``).

    Safe as one path component whatever ``name`` is (a cluster's request is untrusted input). The name
    messages show is the display name either way: the runner gives the grader it (``ClaimedJob``)."""
    suffix = next((suffix for suffix in SUBMISSION_SUFFIXES if name.endswith(suffix)), None)
    stem = name.removesuffix(suffix) if suffix is not None else ""
    if suffix is not None and len(name) <= MAX_DISPLAY_NAME_CHARS and _MODULE_STEM.fullmatch(stem):
        return name
    return GRADING_FALLBACK_NAME.removesuffix(".py") + (suffix or ".py")


def check_upload(client_name: str | None, content: bytes, *, max_bytes: int) -> CheckedUpload:
    """Accept a Python source file or notebook, or say precisely why it cannot be graded.

    Args:
        client_name: The file name the client sent.
        content: The file's bytes (at most ``max_bytes + 1`` were read).
        max_bytes: GYMGRADE_MAX_UPLOAD_BYTES.

    Returns:
        The checked upload.

    Raises:
        UploadTooLarge: More than ``max_bytes`` bytes.
        InvalidUpload: Not a ``.py`` or ``.ipynb`` name, empty, binary (NUL bytes) or not UTF-8.
    """
    if len(content) > max_bytes:
        raise UploadTooLarge(
            f"the file is larger than the limit of {max_bytes} bytes; upload only your opengym.py source"
        )
    name = display_name(client_name)
    suffix = _suffix(name)
    if not suffix or name.lower() == suffix:
        raise InvalidUpload(
            f"expected a Python file named like opengym.py or a notebook named like opengym.ipynb, found the name {name or '(none)'!r}"  # noqa: E501
        )
    if not content.strip():
        raise InvalidUpload(f"{name} is empty; upload the file with your functions in it")
    if b"\x00" in content:
        raise InvalidUpload(f"{name} holds binary data (NUL bytes); expected Python source text")
    try:
        content.decode("utf-8")
    except UnicodeDecodeError as error:
        raise InvalidUpload(
            f"{name} is not UTF-8 text (byte {error.start} is 0x{content[error.start]:02x}); "
            "save it as UTF-8 and upload it again"
        ) from None
    return CheckedUpload(display_name=name, content=content, sha256=hashlib.sha256(content).hexdigest())
