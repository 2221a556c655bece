"""How gymgrade plots: the look and canvas of every plot, and the plotters a problem's declaration names.

Each plotter (`Problem.plot`) is a pure function of the problem's result and its settings, and returns a
title, a caption and a matplotlib figure, or None when the result holds nothing to plot. Every plot, the
class report's too, starts from `new_canvas` (matplotlib's Agg canvas: no pyplot, no display, safe in
threads) and draws in the colours below. matplotlib is imported when a plot is drawn, not when the problems
are declared. `grader.render.figures` encodes the figures for the HTML report, the class report and the
service's page.
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np

from grader.lab.checks.blackjack import BlackjackConfig
from grader.lab.checks.car import CarConfig
from grader.lab.checks.cartpole import CartpoleConfig
from grader.lab.settings import ProblemConfig
from grader.lab.stats import binomial_acceptance
from grader.report import ProblemResult

if TYPE_CHECKING:
    from matplotlib.figure import Figure as PlotFigure

PLOT_SIZE = (6.0, 3.2)
PLOT_DPI = 80
REFERENCE_EPISODES = 100
STUDENT_COLOUR, REFERENCE_COLOUR, EXACT_COLOUR, BAR_COLOUR = "#1f77b4", "#7f7f7f", "#2ca02c", "#d62728"

Plotter: TypeAlias = Callable[[ProblemResult, ProblemConfig], "tuple[str, str, PlotFigure] | None"]
"""Draws a problem's plot from its result and settings: (title, caption, figure), or None."""


def new_canvas() -> PlotFigure:
    """An empty figure of the plots' size on matplotlib's Agg canvas (no pyplot, no display)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure as PlotFigure

    figure = PlotFigure(figsize=PLOT_SIZE, dpi=PLOT_DPI, layout="constrained")
    FigureCanvasAgg(figure)
    return figure


def new_plot() -> tuple[PlotFigure, Any]:
    """A canvas (`new_canvas`) with one set of axes."""
    figure = new_canvas()
    return figure, figure.add_subplot()


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


def plot_blackjack(result: ProblemResult, settings: ProblemConfig) -> tuple[str, str, PlotFigure] | None:
    """The exact win probability of every threshold n, and the student's win rates with their bands."""
    exact, student = _keyed(result.measurements.get("exact_curve")), _keyed(result.measurements.get("curve"))
    if not exact or not isinstance(settings, BlackjackConfig):
        return None
    figure, axes = new_plot()
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


def plot_lengths(result: ProblemResult, settings: ProblemConfig) -> tuple[str, str, PlotFigure] | None:
    """Histogram of the student's episode lengths against the lab's bars and the reference solution's."""
    lengths = _numbers(result.measurements.get("lengths"))
    if not lengths:
        return None
    reference = reference_lengths(settings.problem_id)
    figure, axes = new_plot()
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


def plot_taxi(result: ProblemResult, settings: ProblemConfig) -> tuple[str, str, PlotFigure] | None:
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
    figure = new_canvas()
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


def plot_guess_counts(result: ProblemResult, settings: ProblemConfig) -> tuple[str, str, PlotFigure] | None:
    """The student's guesses per game against the exact distribution of the midpoint search's."""
    from reference.oracles.guessing_game import midpoint_guess_counts

    counts = [int(count) for count in _numbers(result.measurements.get("lengths"))]
    if not counts:
        return None
    oracle = midpoint_guess_counts()
    most = max(oracle.most, *counts)
    guesses = np.arange(1, most + 1)
    figure, axes = new_plot()
    axes.bar(guesses, [counts.count(int(k)) for k in guesses], color=STUDENT_COLOUR, alpha=0.7,
             label="your games")  # fmt: skip
    axes.plot(guesses, [len(counts) * oracle.probability(int(k)) for k in guesses], "o", color=EXACT_COLOUR,
              label="midpoint search (exact expectation)")  # fmt: skip
    axes.set(xlabel="guesses in the game", ylabel="games")
    axes.legend(loc="upper left", fontsize=8)
    caption = f"guessing_game(): how many guesses each of your {len(counts)} replayed games took (bars), against the number of games the midpoint search is expected to finish in each count (exact, {oracle.mean:.3f} guesses on average)."  # noqa: E501
    return "GuessingGame guesses per game", caption, figure
