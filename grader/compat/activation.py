"""Turn the layer on: shim directories on `sys.path`, extra environments registered, scripts run."""

from __future__ import annotations

import os
import runpy
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from . import events
from .envs import register_envs


@dataclass(frozen=True)
class ShimPaths:
    """Directories to put on `sys.path` for code run through the layer.

    Attributes:
        first: goes at the front; holds the classic-API `gym` package.
        fallback: goes at the end; holds a minimal `IPython` used only when IPython is not installed.
    """

    first: Path
    fallback: Path


def shim_paths() -> ShimPaths:
    """Return the layer's shim directories (inside this package; nothing is written there)."""
    here = Path(__file__).resolve().parent
    return ShimPaths(first=here / "shim", fallback=here / "fallback")


def activate() -> ShimPaths:
    """Make `import gym` and `from IPython.display import clear_output` work in this process.

    Puts `shim_paths().first` at the front of `sys.path` and `.fallback` at the end (once), registers
    `NChain-v0` and `GuessingGame-v0`, hides pygame's import banner (it would land in the student's
    output the first time a frame is drawn) and, when there is no display, points SDL at its dummy
    video driver so that drawing `rgb_array` frames needs no window system. Calling it again changes
    nothing.

    Returns:
        The directories added.
    """
    paths = shim_paths()
    first, fallback = str(paths.first), str(paths.fallback)
    if first not in sys.path:
        sys.path.insert(0, first)
    if fallback not in sys.path:
        sys.path.append(fallback)
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    register_envs()
    return paths


def run_script(script: Path, args: Sequence[str] = (), *, summary: TextIO | None = None) -> None:
    """Run `script` as `python script ARGS` would, with the layer active.

    The script runs with `__name__ == "__main__"`, `sys.argv == [script, *args]` and its directory on
    `sys.path`. When it ends, normally or not, a summary of the compatibility events goes to `summary`
    (standard error by default); exceptions and `SystemExit` from the script propagate.

    Args:
        script: path of the Python file to run.
        args: its command-line arguments.
        summary: where to write the event summary.
    """
    sys.argv = [str(script), *args]
    sys.path.insert(0, str(script.resolve().parent))
    activate()
    try:
        runpy.run_path(str(script), run_name="__main__")
    finally:
        print(format_summary(events.drain()), file=summary or sys.stderr)


def format_summary(drained: Sequence[events.CompatEvent]) -> str:
    """A few lines a student can read: what the layer had to tolerate."""
    if not drained:
        return "gymgrade compat: no compatibility events"
    lines = [f"gymgrade compat: {len(drained)} compatibility event(s)"]
    lines += [f"  {event.kind} [{event.env_id}]: {event.detail}" for event in drained]
    return "\n".join(lines)
