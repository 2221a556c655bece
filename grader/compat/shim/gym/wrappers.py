"""`gym.wrappers`: gymnasium's wrappers under their classic name (they expect gymnasium environments).

Names are looked up on first use, as gymnasium does: some wrappers need optional packages.
"""

from __future__ import annotations

from typing import Any

import gymnasium.wrappers


def __getattr__(name: str) -> Any:
    return getattr(gymnasium.wrappers, name)


def __dir__() -> list[str]:
    return dir(gymnasium.wrappers)
