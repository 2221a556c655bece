"""The edition travels in the report: JSON (old reports read as the first edition), text, HTML, Gradescope."""

import json

import pytest

from grader.lab.assignment import load_config
from grader.lab.editions import EDITIONS, edition_label
from grader.lab.editions.choice import edition_config
from grader.render.gradescope import results
from grader.render.html import render_html
from grader.render.text import summary
from grader.report import FIRST_EDITION, ProblemResult, Report

RL1 = EDITIONS["rl1"]
LABEL = "rl1 (Reinforcement Learning 1: Gymnasium)"


def _rl1_report() -> Report:
    problems = [
        ProblemResult(id="epsilon_decay", title="Problem 5: epsilon_decay", status="passed", score=1.0,
                      max_score=1.0, feedback="every value right"),
        ProblemResult(id="taxi", title="Problem 6: Taxi with two tables", status="failed", score=0.0,
                      max_score=1.0, feedback="the means are swapped",
                      measurements={"returned_q_table_mean": 7.9, "exact_q_table_mean": 5.76}),
    ]  # fmt: skip
    return Report(submission="gymnasium.py", sha256="0" * 64, seed=3, edition="rl1", gymnasium_version="1",
                  grader_version="1", score=1.0, max_score=2.0, problems=problems)  # fmt: skip


def test_a_report_older_than_editions_reads_as_the_first_edition() -> None:
    old = '{"submission": "opengym.py", "sha256": "00", "seed": 1, "gymnasium_version": "1", ' \
        '"grader_version": "1", "score": 0, "max_score": 5}'  # fmt: skip
    assert Report.model_validate_json(old).edition == FIRST_EDITION == "classic" == EDITIONS["classic"].name
    again = Report.model_validate_json(_rl1_report().to_json())
    assert again.edition == "rl1" and again == _rl1_report()


def test_the_text_summary_html_page_and_gradescope_output_name_the_edition() -> None:
    report = _rl1_report()
    assert f"Edition: {LABEL}" in summary(report).splitlines()
    page = render_html(report, load_config(RL1.default_config))
    assert f"edition {LABEL}" in page and "Problem 6: Taxi with two tables" in page
    assert f"Edition: {LABEL}." in results(report).output


def test_an_unknown_edition_is_shown_as_named() -> None:
    assert edition_label("rl9") == "rl9"
    assert edition_label("classic") == "classic (OpenGym AI (classic gym))"


def test_a_reports_figures_are_drawn_with_its_editions_configuration() -> None:
    assert edition_config("rl1") == RL1.default_config
    assert edition_config("classic") is None and edition_config("volume2") is None
    assert edition_config("rl9") is None, "a report from a newer gymgrade: the first edition's"


@pytest.mark.parametrize("name", list(EDITIONS))
def test_every_editions_report_renders_in_every_format(name: str) -> None:
    edition = EDITIONS[name]
    first = edition.registry.problems[0]
    result = ProblemResult(id=first.id, title=first.title, status="missing", score=0.0, max_score=1.0,
                           feedback="not attempted yet")  # fmt: skip
    report = Report(submission=edition.notebook_name, sha256="0" * 64, seed=1, edition=name,
                    gymnasium_version="1", grader_version="1", score=0.0, max_score=1.0,
                    problems=[result])  # fmt: skip
    label = edition_label(name)
    assert f"Edition: {label}" in summary(report).splitlines()
    assert f"edition {label}" in render_html(report, load_config(edition_config(name)))
    assert f"Edition: {label}." in results(report).output
    assert Report.model_validate_json(report.to_json()).edition == name


RL2_LABEL = "rl2 (Policy Function Iteration / Reinforcement Learning 2)"


def _rl2_report() -> Report:
    problem = ProblemResult(id="value_iteration", title="Problem 1: value_iteration", status="passed",
                            score=1.0, max_score=1.0, feedback="the optimal values")  # fmt: skip
    return Report(submission="policy_iteration.py", sha256="0" * 64, seed=3, lab="rl2", edition="v2024",
                  gymnasium_version="1", grader_version="1", score=1.0, max_score=1.0,
                  problems=[problem])  # fmt: skip


def test_a_report_older_than_the_second_lab_reads_as_the_first_lab_and_keeps_its_other_keys() -> None:
    from grader.report import FIRST_LAB

    old = '{"submission": "opengym.py", "sha256": "00", "seed": 1, "gymnasium_version": "1", ' \
        '"grader_version": "1", "score": 0, "max_score": 5, "edition": "rl1"}'  # fmt: skip
    read = Report.model_validate_json(old)
    assert (read.lab, read.edition) == (FIRST_LAB, "rl1") == ("opengym", "rl1")
    keys = list(json.loads(_rl1_report().to_json()))
    assert keys[keys.index("config_sha256") + 1 : keys.index("edition") + 1] == ["lab", "edition"]
    again = Report.model_validate_json(_rl2_report().to_json())
    assert again == _rl2_report() and again.lab == "rl2"


def test_the_text_summary_html_page_and_gradescope_output_name_the_lab() -> None:
    report = _rl2_report()
    lines = summary(report).splitlines()
    assert lines.index(f"Lab: {RL2_LABEL}") + 1 == lines.index(
        "Edition: v2024 (Reinforcement Learning 2: Markov Decision Process (2024))"
    )
    page = render_html(report, load_config(EDITIONS["v2024"].default_config))
    assert f"lab {RL2_LABEL} · edition v2024" in page
    assert f"Lab: {RL2_LABEL}." in results(report).output
    first = summary(_rl1_report()).splitlines()
    assert "Lab: opengym (OpenGym AI / Reinforcement Learning 1)" in first
