"""Silence the gymnasium warnings that lab-literal code triggers, and only those."""

from __future__ import annotations

import re
import warnings
from collections.abc import Iterator
from contextlib import contextmanager

# Messages gymnasium emits for things the lab does on purpose (an old version such as CartPole-v0) or
# that the layer has already recorded as a CompatEvent (stepping after done). Matched anywhere in the
# message because gymnasium prefixes its own colour codes.
OUT_OF_DATE = "is out of date. You should consider upgrading"
STEP_AFTER_TERMINATED = "even though this environment has already returned terminated = True"


@contextmanager
def quiet_gymnasium(*messages: str) -> Iterator[None]:
    """Ignore warnings whose message contains one of `messages` inside the `with` block.

    Every other warning, the student's own included, is still shown.
    """
    with warnings.catch_warnings():
        for message in messages:
            warnings.filterwarnings("ignore", message=f".*{re.escape(message)}")
        yield
