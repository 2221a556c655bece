"""The report's figures: plots of a problem's measurements against the exact answers, and episode replays.

Plots are PNGs drawn with matplotlib's Agg canvas (no pyplot, no display, safe in threads); replays are
animated GIFs re-rendered headless (``rgb_array``) in the grader's own gymnasium from the episode's reset
seed and actions. Both are small: a plot is 480x256 pixels; a GIF keeps at most ``MAX_GIF_FRAMES`` frames
(every k-th step, and always the last) at most ``MAX_GIF_WIDTH`` pixels wide, on one 64-colour palette.
"""

from __future__ import annotations

import base64
import functools
import io
import math
import os
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure as PlotFigure
from PIL import Image

from grader.config import AssignmentConfig, BlackjackConfig, CarConfig, CartpoleConfig
from grader.report import EpisodeReplay, ProblemResult
from grader.stats import binomial_acceptance

MAX_GIF_FRAMES = 60
MAX_GIF_WIDTH = 240
GIF_COLOURS = 64
GIF_SECONDS = 5.0
"""Target playing time of a replay; each frame shows for 40 to 200 ms."""
PLOT_SIZE = (6.0, 3.2)
PLOT_DPI = 80
REFERENCE_EPISODES = 100
STUDENT_COLOUR, REFERENCE_COLOUR, EXACT_COLOUR, BAR_COLOUR = "#1f77b4", "#7f7f7f", "#2ca02c", "#d62728"


@dataclass(frozen=True)
class Figure:
    """One image of the report.

    Attributes:
        problem: The problem it belongs to.
        title: A short title (also the image's alternative text).
        caption: What it shows and how to read it.
        mime: ``image/png`` or ``image/gif``.
        data: The encoded image.
        seconds: Time it took to draw.
    """

    problem: str
    title: str
    caption: str
    mime: str
    data: bytes
    seconds: float

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
    plotter = PLOTTERS.get(result.id)
    if plotter is not None:
        started = time.perf_counter()
        drawn = plotter(result, config)
        if drawn is not None:
            title, caption, plot = drawn
            figures.append(Figure(result.id, title, caption, "image/png", _png(plot), _since(started)))
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


def _new_plot() -> tuple[PlotFigure, Any]:
    figure = PlotFigure(figsize=PLOT_SIZE, dpi=PLOT_DPI, layout="constrained")
    FigureCanvasAgg(figure)
    return figure, figure.add_subplot()


def _png(figure: PlotFigure) -> bytes:
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png")
    return buffer.getvalue()


def _numbers(values: object) -> list[float]:
    if not isinstance(values, list):
        return []
    return [
        float(value) for value in values if isinstance(value, int | float) and not isinstance(value, bool)
    ]


def _keyed(values: object) -> dict[int, float]:
    if not isinstance(values, dict):
        return {}
    return {int(key): float(value) for key, value in values.items() if isinstance(value, int | float)}


def plot_blackjack(result: ProblemResult, config: AssignmentConfig) -> tuple[str, str, PlotFigure] | None:
    """The exact win probability of every threshold n, and the student's win rates with their bands."""
    settings = config.problem("blackjack")
    exact, student = _keyed(result.measurements.get("exact_curve")), _keyed(result.measurements.get("curve"))
    if not exact or not isinstance(settings, BlackjackConfig):
        return None
    figure, axes = _new_plot()
    xs = sorted(exact)
    axes.plot(xs, [exact[n] for n in xs], color=EXACT_COLOUR, label="exact win probability")
    for index, (n, rate) in enumerate(sorted(student.items())):
        band = binomial_acceptance(settings.games_per_call, exact.get(n, 0.0), settings.win_rate_alpha)
        low, high = band.low / band.trials, band.high / band.trials
        axes.plot([n, n], [low, high], color=STUDENT_COLOUR, linewidth=6, alpha=0.25,
                  label="accepted band" if index == 0 else None)  # fmt: skip
        axes.plot([n], [rate], "o", color=STUDENT_COLOUR, label="your win rate" if index == 0 else None)
    axes.set(
        xlabel="n (draw while the hand is at most n)", ylabel="win rate", xlim=(min(xs) - 0.5, max(xs) + 0.5)
    )
    axes.legend(loc="lower left", fontsize=8)
    caption = (
        "blackjack(n): the line is the exact probability of winning when drawing on hands up to n; "
        f"each dot is what your function returned, and its shaded band the win rates {settings.games_per_call:,} games of a correct policy land in with probability 1 - {settings.win_rate_alpha:g}."  # noqa: E501
    )
    return "Blackjack win rate against n", caption, figure


@functools.cache
def reference_lengths(problem: str, episodes: int = REFERENCE_EPISODES) -> tuple[int, ...]:
    """Episode lengths of the reference solution (seeds 0..episodes-1), computed once per process."""
    from reference import solutions

    play: Callable[..., int] = solutions.cartpole if problem == "cartpole" else solutions.car
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return tuple(play(seed=seed) for seed in range(episodes))


def plot_lengths(result: ProblemResult, config: AssignmentConfig) -> tuple[str, str, PlotFigure] | None:
    """Histogram of the student's episode lengths against the lab's bars and the reference solution's."""
    lengths = _numbers(result.measurements.get("lengths"))
    settings = config.problem("cartpole" if result.id == "cartpole" else "car")
    if not lengths:
        return None
    reference = reference_lengths(result.id)
    figure, axes = _new_plot()
    bins = np.linspace(0, max(200, *lengths, *reference) + 1, 41)
    axes.hist(reference, bins=bins, color=REFERENCE_COLOUR, alpha=0.5, label="reference solution")
    axes.hist(lengths, bins=bins, color=STUDENT_COLOUR, alpha=0.7, label="your episodes")
    mean = float(np.mean(lengths))
    axes.axvline(mean, color=STUDENT_COLOUR, linestyle="--", label=f"your mean {mean:.1f}")
    if isinstance(settings, CartpoleConfig):
        axes.axvline(settings.min_steps, color=BAR_COLOUR, label=f"every episode >= {settings.min_steps}")
        axes.axvline(settings.min_mean_steps, color=BAR_COLOUR, linestyle=":",
                     label=f"mean >= {settings.min_mean_steps:g}")  # fmt: skip
        game, rule = "CartPole", "the pole must stay up: longer is better"
    elif isinstance(settings, CarConfig):
        axes.axvline(settings.max_mean_steps, color=BAR_COLOUR, linestyle=":",
                     label=f"mean < {settings.max_mean_steps:g}")  # fmt: skip
        game, rule = "MountainCar", "the car must reach the flag: shorter is better"
    else:
        return None
    axes.set(xlabel="steps in the episode", ylabel="episodes")
    axes.legend(loc="upper left", fontsize=8)
    caption = f"{game} episode lengths ({rule}): your {len(lengths)} replayed episodes, the lab's bars in red, and {len(reference)} episodes of the reference solution in grey."  # noqa: E501
    return f"{game} episode lengths", caption, figure


def plot_taxi(result: ProblemResult, config: AssignmentConfig) -> tuple[str, str, PlotFigure] | None:
    """The two averages taxi() returned against the exact expectations and their tolerances."""
    measured = result.measurements
    pairs = [
        ("random actions", "returned_random_mean", "exact_random_mean", "random_tolerance"),
        ("Q-table", "returned_q_mean", "exact_q_mean", "q_tolerance"),
    ]
    rows: list[tuple[str, float, float, float]] = []
    for label, *keys in pairs:
        values = [measured.get(key) for key in keys]
        numbers = [float(value) for value in values if isinstance(value, int | float)]
        if len(numbers) == len(keys):
            rows.append((label, numbers[0], numbers[1], numbers[2]))
    if not rows:
        return None
    figure = PlotFigure(figsize=PLOT_SIZE, dpi=PLOT_DPI, layout="constrained")
    FigureCanvasAgg(figure)
    for index, (label, returned, exact, tolerance) in enumerate(rows):
        axes = figure.add_subplot(1, len(rows), index + 1)
        axes.axhspan(exact - tolerance, exact + tolerance, color=EXACT_COLOUR, alpha=0.2, label="accepted")
        axes.axhline(exact, color=EXACT_COLOUR, label="exact expectation")
        axes.plot([0], [returned], "o", color=STUDENT_COLOUR, label="your average")
        spread = max(abs(returned - exact), tolerance) * 1.6
        axes.set(title=label, xticks=[], ylim=(exact - spread, exact + spread), ylabel="mean total reward")
        axes.legend(loc="lower right", fontsize=7)
    caption = "taxi(): the average total rewards your function returned, against the exact expected return of random play and of the Q-table's greedy policy, with the band a correct answer lands in."  # noqa: E501
    return "Taxi average returns", caption, figure


def plot_guess_counts(result: ProblemResult, config: AssignmentConfig) -> tuple[str, str, PlotFigure] | None:
    """The student's guesses per game against the exact distribution of the midpoint search's."""
    from reference.oracles.guessing_game import midpoint_guess_counts

    counts = [int(count) for count in _numbers(result.measurements.get("lengths"))]
    if not counts:
        return None
    oracle = midpoint_guess_counts()
    most = max(oracle.most, *counts)
    guesses = np.arange(1, most + 1)
    figure, axes = _new_plot()
    axes.bar(guesses, [counts.count(int(k)) for k in guesses], color=STUDENT_COLOUR, alpha=0.7,
             label="your games")  # fmt: skip
    axes.plot(guesses, [len(counts) * oracle.probability(int(k)) for k in guesses], "o", color=EXACT_COLOUR,
              label="midpoint search (exact expectation)")  # fmt: skip
    axes.set(xlabel="guesses in the game", ylabel="games")
    axes.legend(loc="upper left", fontsize=8)
    caption = f"guessing_game(): how many guesses each of your {len(counts)} replayed games took (bars), against the number of games the midpoint search is expected to finish in each count (exact, {oracle.mean:.3f} guesses on average)."  # noqa: E501
    return "GuessingGame guesses per game", caption, figure


PLOTTERS: dict[str, Callable[[ProblemResult, AssignmentConfig], tuple[str, str, PlotFigure] | None]] = {
    "blackjack": plot_blackjack,
    "cartpole": plot_lengths,
    "car": plot_lengths,
    "taxi": plot_taxi,
    "guessing_game": plot_guess_counts,
}
"""The problems with a plot, and how each is drawn (the replays are chosen in grader.showcase)."""


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
