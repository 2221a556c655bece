"""Measure what the lab-compatibility layer (grader.compat) costs per step, render and clear_output."""

from __future__ import annotations

import importlib.util
import platform
import time
from collections.abc import Callable
from typing import Any

import gymnasium
import numpy as np

from grader.compat import make, shim_paths

STEPS = 100_000
REPEATS = 7


def _per_step_microseconds(env: Any, actions: list[Any], *, classic: bool) -> float:
    env.reset(seed=0)
    step, reset = env.step, env.reset
    started = time.perf_counter()
    for action in actions:
        result = step(action)
        if result[2] or (not classic and result[3]):
            reset()
    return (time.perf_counter() - started) / len(actions) * 1e6


def _interleaved(actions: list[Any]) -> tuple[float, float]:
    """Best of REPEATS for gymnasium and for the layer, alternating so that load affects both alike."""
    native, layered = [], []
    for _ in range(REPEATS):
        native.append(_per_step_microseconds(gymnasium.make("Taxi-v4"), actions, classic=False))
        layered.append(_per_step_microseconds(make("Taxi-v3"), actions, classic=True))
    return min(native), min(layered)


def _best(measure: Callable[[], float]) -> float:
    return min(measure() for _ in range(REPEATS))


def _fallback_clear_output() -> Callable[..., None]:
    spec = importlib.util.spec_from_file_location(
        "fallback_display", shim_paths().fallback / "IPython" / "display.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    clear_output: Callable[..., None] = module.clear_output
    return clear_output


def main() -> None:
    """Print the figures recorded in bench/RESULTS.md under "Compat layer"."""
    print(
        f"machine: {platform.processor() or platform.machine()}, python {platform.python_version()}, "
        f"gymnasium {gymnasium.__version__}; best of {REPEATS}, {STEPS} Taxi steps each"
    )
    drawn = np.random.default_rng(0).integers(0, 6, STEPS)
    for label, actions in (
        ("python int actions", [int(a) for a in drawn]),
        ("numpy int64 actions", list(drawn)),
    ):
        native, layered = _interleaved(actions)
        print(
            f"Taxi step, {label}: gymnasium {native:.2f} us, through the layer {layered:.2f} us "
            f"(+{layered - native:.2f} us, {100 * (layered - native) / native:+.0f}%)"
        )
    env = make("Acrobot-v1")
    env.reset(seed=0)
    render = _best(lambda: _timed(env.render, 100_000))
    print(f"render() without mode: {render:.3f} us per call")
    clear_output = _fallback_clear_output()
    clear = _best(lambda: _timed(lambda: clear_output(wait=True), 100_000))
    print(f"fallback clear_output(wait=True): {clear:.3f} us per call (find_qvalues calls it 1000 times)")


def _timed(function: Callable[[], Any], calls: int) -> float:
    started = time.perf_counter()
    for _ in range(calls):
        function()
    return (time.perf_counter() - started) / calls * 1e6


if __name__ == "__main__":
    main()
