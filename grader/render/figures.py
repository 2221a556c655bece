"""The figures gymgrade shows: plots of a problem's measurements against the exact answers, and replays.

One stack draws them for the HTML report, the class report (`grader.classroom.report.figures`) and the
service's page (`api.web.page_figures`). Plots are PNGs drawn by `grader.lab.plots` (matplotlib's Agg canvas:
no pyplot, no display, safe in threads); replays are animated GIFs re-rendered headless (``rgb_array``) in the
grader's own gymnasium from the episode's reset seed and actions. Both are small: a plot is 480x256 pixels; a
GIF keeps at most ``MAX_GIF_FRAMES`` frames (every k-th step, and always the last) at most ``MAX_GIF_WIDTH``
pixels wide, on one 64-colour palette.
"""

from __future__ import annotations

import base64
import io
import math
import os
import time
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from matplotlib.figure import Figure as PlotFigure
from PIL import Image

from grader.errors import UnknownProblem
from grader.lab.assignment import AssignmentConfig
from grader.report import EpisodeReplay, ProblemResult

MAX_GIF_FRAMES = 60
MAX_GIF_WIDTH = 240
GIF_COLOURS = 64
GIF_SECONDS = 5.0
"""Target playing time of a replay; each frame shows for 40 to 200 ms."""


@dataclass(frozen=True)
class Figure:
    """One image of the report.

    Attributes:
        problem: The problem it belongs to.
        title: A short title (also the image's alternative text).
        caption: What it shows and how to read it.
        mime: ``image/png`` or ``image/gif``.
        data: The encoded image.
        seconds: Time it took to draw (not part of what the figure is: equal figures may differ in it).
    """

    problem: str
    title: str
    caption: str
    mime: str
    data: bytes
    seconds: float = field(compare=False)

    def data_uri(self) -> str:
        """The image as a ``data:`` URI, to embed in a self-contained page."""
        return f"data:{self.mime};base64,{base64.b64encode(self.data).decode('ascii')}"


def problem_figures(result: ProblemResult, config: AssignmentConfig) -> list[Figure]:
    """Every figure for one problem's result: its plot (when its measurements hold one) and its replay.

    Args:
        result: The problem's result from the report.
        config: The assignment configuration it was graded with (the bars and tolerances).

    Returns:
        The figures, plot first; none for a result without measurements or replay.
    """
    figures: list[Figure] = []
    try:
        plotter = config.registry.problem(result.id).plot
    except UnknownProblem:
        plotter = None  # a result of a problem this edition does not declare: its replay only
    if plotter is not None:
        started = time.perf_counter()
        drawn = plotter(result, config.problem(result.id))
        if drawn is not None:
            figures.append(png_figure(result.id, *drawn, started=started))
    if result.replay is not None:
        started = time.perf_counter()
        gif, shown = replay_gif(result.replay)
        caption = f"Replay of {result.replay.label}: {result.replay.length} steps, total reward {result.replay.total_reward:g}, re-played by the grader from the episode's seed and your actions ({shown} frames shown)."  # noqa: E501
        figures.append(
            Figure(result.id, f"Replay: {result.replay.env_id}", caption, "image/gif", gif, _since(started))
        )
    return figures


def _since(started: float) -> float:
    return time.perf_counter() - started


def png_figure(problem: str, title: str, caption: str, plot: PlotFigure, *, started: float) -> Figure:
    """A drawn plot encoded as a PNG `Figure`.

    Args:
        problem: What it belongs to (a problem id, or the class report's ``class``).
        title: Its title.
        caption: Its caption.
        plot: The matplotlib figure.
        started: `time.perf_counter()` when its drawing began (for `Figure.seconds`).
    """
    buffer = io.BytesIO()
    plot.savefig(buffer, format="png")
    return Figure(problem, title, caption, "image/png", buffer.getvalue(), _since(started))


def replay_gif(replay: EpisodeReplay) -> tuple[bytes, int]:
    """Re-render an episode headless and encode it as a small looping GIF.

    Returns:
        The GIF and how many frames it holds.
    """
    import gymnasium

    from grader.compat import resolve_env_id

    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")  # rgb_array needs no window
    target = resolve_env_id(replay.env_id)
    stride = max(1, math.ceil((replay.length + 1) / MAX_GIF_FRAMES))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = gymnasium.make(target.gymnasium_id, render_mode="rgb_array", **target.kwargs)
        try:
            env.reset(seed=replay.reset_seed)
            frames = [_frame(env.render())]
            for step, action in enumerate(replay.actions, start=1):
                _, _, terminated, truncated, _ = env.step(action)
                if step % stride == 0 or terminated or truncated or step == len(replay.actions):
                    frames.append(_frame(env.render()))
                if terminated or truncated:
                    break
        finally:
            env.close()
    return _gif(frames), len(frames)


def _frame(rendered: object) -> Image.Image:
    image = Image.fromarray(np.asarray(rendered, dtype=np.uint8))
    if image.width > MAX_GIF_WIDTH:
        image = image.resize(
            (MAX_GIF_WIDTH, round(image.height * MAX_GIF_WIDTH / image.width)), Image.Resampling.BILINEAR
        )
    return image


def _gif(frames: Sequence[Image.Image]) -> bytes:
    # One palette for the whole animation (first, middle and last frames): fast, and no flicker.
    sample = Image.fromarray(
        np.concatenate([np.asarray(frames[i]) for i in (0, len(frames) // 2, -1)], axis=0)
    )
    palette = sample.quantize(colors=GIF_COLOURS, method=Image.Quantize.FASTOCTREE)
    images = [frame.quantize(palette=palette, dither=Image.Dither.NONE) for frame in frames]
    duration = min(max(round(GIF_SECONDS * 1000 / len(images)), 40), 200)
    buffer = io.BytesIO()
    images[0].save(buffer, format="GIF", save_all=True, append_images=images[1:], loop=0, duration=duration,
                   optimize=True)  # fmt: skip
    return buffer.getvalue()


def all_figures(results: Sequence[ProblemResult], config: AssignmentConfig) -> dict[str, list[Figure]]:
    """The figures of every problem of a report, by problem id."""
    return {result.id: problem_figures(result, config) for result in results}
