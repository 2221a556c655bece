"""The Content-Security-Policy of every page gymgrade writes: nothing loads or runs but its own stylesheet.

A report page (a student's, the class's, the similarity ranking) is one self-contained file that may be
mailed, uploaded to a learning platform or opened from disk: no script, no network, no form, and only the
page's own stylesheet, pinned by its hash; pages with plots also allow their ``data:`` images.
"""

from __future__ import annotations

import base64
import hashlib


def content_security_policy(style: str, *, images: bool = True) -> str:
    """The policy of a page whose only stylesheet is ``style``.

    Args:
        style: The page's stylesheet, exactly as it stands in its ``<style>`` element.
        images: Whether the page shows ``data:`` images (plots, replays).

    Returns:
        The policy, for the page's ``<meta http-equiv="Content-Security-Policy">``.
    """
    digest = base64.b64encode(hashlib.sha256(style.encode()).digest()).decode()
    allowed_images = "img-src data:; " if images else ""
    style_source = f"style-src 'sha256-{digest}'"
    return f"default-src 'none'; {allowed_images}{style_source}; base-uri 'none'; form-action 'none'"
