"""The page's figures are the HTML report's, drawn per problem by `grader.render.figures`, also while it
grades."""

from __future__ import annotations

from typing import Any

import pytest
from pydantic import JsonValue

from api.web import page_figures
from grader.lab.assignment import load_config
from grader.lab.editions import DEFAULT_EDITION, EDITIONS
from grader.lab.editions.choice import edition_config
from grader.render.figures import problem_figures
from grader.report import EpisodeReplay, ProblemResult

CARTPOLE_ACTIONS = [0, 1] * 6 + [0] * 5
"""The actions of a short CartPole-v1 episode, replayed from reset seed 7."""


def _results() -> list[ProblemResult]:
    exact: dict[str, JsonValue] = {str(n): 0.38 + 0.002 * n for n in range(22)}
    steps = len(CARTPOLE_ACTIONS)
    replay = EpisodeReplay(label="your shortest", env_id="CartPole-v1", reset_seed=7,
                           actions=CARTPOLE_ACTIONS, length=steps, total_reward=float(steps))  # fmt: skip
    return [
        ProblemResult(id="random_blackjack", title="Problem 1", status="passed", score=1, max_score=1,
                      feedback="ok", measurements={"returned": 0.28}),
        ProblemResult(id="blackjack", title="Problem 2", status="passed", score=1, max_score=1, feedback="ok",
                      measurements={"exact_curve": exact, "curve": {"12": 0.41, "20": 0.42}}),
        ProblemResult(id="cartpole", title="Problem 3", status="failed", score=0, max_score=1,
                      feedback="short", measurements={"lengths": [150, 90, 200, 180]}, replay=replay),
    ]  # fmt: skip


def _page_problems(results: list[ProblemResult]) -> list[dict[str, Any]]:
    """The problems as a student's page gets them: plain JSON, with the grading seed nulled."""
    return [{**result.model_dump(mode="json"), "seed": None} for result in results]


@pytest.mark.slow  # a grading through the sandbox
def test_each_problem_shows_the_html_reports_figures_byte_for_byte() -> None:
    results = _results()
    shown = page_figures(_page_problems(results), "classic")
    config = load_config(None)
    assert {problem: [figure.title for figure in figures] for problem, figures in shown.items()} == {
        "random_blackjack": [],
        "blackjack": ["Blackjack win rate against n"],
        "cartpole": ["CartPole episode lengths", "Replay: CartPole-v1"],
    }
    for result in results:
        expected = problem_figures(result, config)
        assert [(f.mime, f.caption, f.data) for f in shown[result.id]] == [
            (f.mime, f.caption, f.data) for f in expected
        ]


def test_a_problem_is_drawn_once_and_its_figures_reused_on_every_refresh() -> None:
    problems = _page_problems(_results())
    first = page_figures(problems[:2], None)
    again = page_figures(problems, None)
    assert again["blackjack"][0] is first["blackjack"][0]


def test_withheld_and_foreign_entries_show_no_figures_and_leave_the_others_theirs() -> None:
    blackjack = _page_problems(_results())[1]
    withheld = {**blackjack, "id": "taxi", "status": "withheld", "score": None}
    foreign = {"id": "curve", "status": "passed", "measurements": {"curve": [1, 2, 3]}}
    shown = page_figures([withheld, foreign, {"title": "no id"}, blackjack], "classic")
    assert list(shown) == ["blackjack"]
    assert [figure.title for figure in shown["blackjack"]] == ["Blackjack win rate against n"]


@pytest.mark.parametrize("name", list(EDITIONS))
def test_while_grading_runs_the_first_editions_plotters_draw_as_the_reports_edition(name: str) -> None:
    # No report yet means no edition: the page draws with the first edition's declarations and settings.
    edition, first = EDITIONS[name], EDITIONS[DEFAULT_EDITION]
    config, first_config = load_config(edition_config(name)), load_config(None)
    for problem in edition.registry.problems:
        if problem.plot is not None:
            assert first.registry.problem(problem.id).plot is problem.plot, problem.id
            assert first_config.problem(problem.id) == config.problem(problem.id), problem.id


def test_while_grading_runs_a_problem_another_edition_declares_is_not_drawn_as_the_first_editions() -> None:
    # rl1's taxi (two tables) has no plot; the first edition's taxi plotter finds none of its measurements.
    measurements: dict[str, Any] = {"returned_q_table_mean": 7.9, "returned_q_table_decay_mean": 7.8,
                                    "exact_q_table_mean": 7.93, "exact_q_table_decay_mean": 7.93}  # fmt: skip
    taxi = ProblemResult(id="taxi", title="Problem 6", status="passed", score=1, max_score=1, feedback="ok",
                         measurements=measurements)  # fmt: skip
    assert page_figures(_page_problems([taxi]), None) == {"taxi": []}
    assert page_figures(_page_problems([taxi]), "rl1") == {"taxi": []}


@pytest.mark.parametrize(
    ("report", "lab", "edition"),
    [
        ({"lab": "rl2", "edition": "v2024"}, "rl2 (Policy Function Iteration / Reinforcement Learning 2)",
         "v2024 (Reinforcement Learning 2: Markov Decision Process (2024))"),
        ({}, "opengym (OpenGym AI / Reinforcement Learning 1)", "classic (OpenGym AI (classic gym))"),
    ],
    ids=["second-lab", "a-report-older-than-labs"],
)  # fmt: skip
def test_the_students_page_names_the_lab_and_edition(report: dict[str, Any], lab: str, edition: str) -> None:
    from api.web import templates

    shown = {"score": 1, "max_score": 1, "problems": [], **report}
    submission = {"status": "done", "progress": [], "report": shown, "overrides": [], "error": None}
    page = templates.env.get_template("_live.html").render(submission=submission, final=True)
    assert f'<p id="lab" class="meta">Lab: {lab}</p>' in page
    assert f'<p id="edition" class="meta">Edition: {edition}</p>' in page
