"""One Content-Security-Policy for every page gymgrade writes, pinned to the letter."""

from __future__ import annotations

import pytest

from grader.classroom.report import CSP as CLASS_CSP
from grader.classroom.similarity.html_output import CSP as SIMILARITY_CSP
from grader.render.csp import content_security_policy
from grader.render.html import CSP as REPORT_CSP

EMPTY_STYLE_DIGEST = "47DEQpj8HBSa+/TImW+5JCeuQeRkm5NMpJWZG3hSuFU="
"""sha256 of the empty string, base64: the hash a browser computes for an empty ``<style>``."""


@pytest.mark.parametrize(
    ("images", "expected"),
    [
        (
            True,
            f"default-src 'none'; img-src data:; style-src 'sha256-{EMPTY_STYLE_DIGEST}'; "
            "base-uri 'none'; form-action 'none'",
        ),
        (
            False,
            f"default-src 'none'; style-src 'sha256-{EMPTY_STYLE_DIGEST}'; "
            "base-uri 'none'; form-action 'none'",
        ),
    ],
    ids=["with-images", "text-only"],
)
def test_the_policy_allows_only_the_pages_own_style_and_data_images(images: bool, expected: str) -> None:
    assert content_security_policy("", images=images) == expected


@pytest.mark.parametrize(
    ("policy", "images"),
    [(REPORT_CSP, True), (CLASS_CSP, True), (SIMILARITY_CSP, False)],
    ids=["student-report", "class-report", "similarity"],
)
def test_every_page_uses_the_one_policy(policy: str, images: bool) -> None:
    allows_images = "img-src data:; " in policy
    assert allows_images == images
    assert policy.startswith("default-src 'none'; ") and policy.endswith(
        "; base-uri 'none'; form-action 'none'"
    )
