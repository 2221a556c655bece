"""The class page's figures: the score histogram and each problem's pass rate, like the student report's.

Drawn by the report's plotting stack: the canvas and colours of ``grader.lab.plots``, encoded by
``grader.render.figures`` as PNGs embedded as ``data:`` URIs. Labels are the problems' registry ids (never
student text).
"""

from __future__ import annotations

import time
from collections.abc import Callable

from matplotlib.figure import Figure as PlotFigure

from grader.classroom.report.summary import ClassSummary
from grader.lab.plots import BAR_COLOUR, EXACT_COLOUR, STUDENT_COLOUR, new_plot
from grader.render.figures import Figure, png_figure

TICK_CHARS = 24
CLASS_FIGURE = "class"
"""The ``problem`` of every class figure (they belong to no single problem)."""


def class_figures(summary: ClassSummary) -> list[Figure]:
    """The score histogram and the pass-rate bars; each left out when there is nothing to plot.

    Args:
        summary: The class summary.

    Returns:
        The figures, histogram first.
    """
    figures: list[Figure] = []
    if summary.scores.count:
        figures.append(_drawn(score_histogram, summary))
    if any(problem.graded for problem in summary.problems):
        figures.append(_drawn(pass_rate_bars, summary))
    return figures


def score_histogram(summary: ClassSummary) -> tuple[str, str, PlotFigure]:
    """How many submissions scored in each tenth of the points, with the mean marked."""
    scores = summary.scores
    figure, axes = new_plot()
    width = (scores.bins[0].high - scores.bins[0].low) or 1.0
    axes.bar([row.low for row in scores.bins], [row.count for row in scores.bins], width=width * 0.95,
             align="edge", color=STUDENT_COLOUR, alpha=0.8, label="submissions")  # fmt: skip
    if scores.mean is not None:
        axes.axvline(scores.mean, color=BAR_COLOUR, linestyle="--", label=f"mean {scores.mean:.3g}")
    axes.set(xlabel=f"score (of {scores.max_score:g})", ylabel="submissions")
    axes.yaxis.get_major_locator().set_params(integer=True)
    axes.legend(loc="upper left", fontsize=8)
    caption = f"Scores of the {scores.count} submissions with a report (a submission that could not be graded scores 0), in {len(scores.bins)} equal bins from 0 to {scores.max_score:g}; the dashed line is the mean, the median is {scores.median:g}."  # noqa: E501
    return "Score distribution", caption, figure


def pass_rate_bars(summary: ClassSummary) -> tuple[str, str, PlotFigure]:
    """Each problem's share of passing submissions among those that ran it."""
    rows = [problem for problem in summary.problems if problem.graded]
    figure, axes = new_plot()
    positions = list(range(len(rows)))
    rates = [problem.pass_rate or 0.0 for problem in rows]
    axes.bar(positions, rates, color=EXACT_COLOUR, alpha=0.8)
    for position, problem in zip(positions, rows, strict=True):
        axes.text(position, (problem.pass_rate or 0.0) + 0.02, f"{problem.passed}/{problem.graded}",
                  ha="center", fontsize=8)  # fmt: skip
    axes.set(xticks=positions, ylim=(0, 1.12), ylabel="pass rate")
    # Ids come from the reports; never let matplotlib read one as mathtext ($...$).
    axes.set_xticklabels(
        [problem.id[:TICK_CHARS] for problem in rows], rotation=20, fontsize=8, parse_math=False
    )
    caption = "Pass rate of each problem: the share of graded submissions that passed it (above each bar: passed / graded; a problem skipped for a submission is not counted)."  # noqa: E501
    return "Pass rate per problem", caption, figure


def _drawn(plotter: Callable[[ClassSummary], tuple[str, str, PlotFigure]], summary: ClassSummary) -> Figure:
    started = time.perf_counter()
    return png_figure(CLASS_FIGURE, *plotter(summary), started=started)
