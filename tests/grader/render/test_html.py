"""The self-contained HTML report: its plots and replays, their size, Chromium rendering it under its CSP."""

from __future__ import annotations

import io
import shutil
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import pytest
from PIL import Image

from grader.lab.assignment import load_config
from grader.render.figures import MAX_GIF_FRAMES, MAX_GIF_WIDTH, all_figures, replay_gif
from grader.render.html import CSP, render_html
from grader.report import EpisodeReplay, ProblemResult, Report
from reference.oracles.taxi import optimal_q_table
from reference.solutions import cartpole_policy, mountain_car_policy

CHROMIUM = "/usr/bin/chromium"
SHORTEST = "your shortest of 4 CartPole episodes"


def _episode(env_id: str, policy: Callable[[Any], int], seed: int, label: str) -> EpisodeReplay:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # CartPole-v0 is the lab's game
        env = gymnasium.make(env_id)
    observation, _ = env.reset(seed=seed)
    actions: list[int] = []
    total, done = 0.0, False
    while not done:
        action = int(policy(observation))
        observation, reward, terminated, truncated, _ = env.step(action)
        actions.append(action)
        total += float(reward)
        done = terminated or truncated
    return EpisodeReplay(
        label=label, env_id=env_id, reset_seed=seed, actions=actions, length=len(actions), total_reward=total
    )


@pytest.fixture(scope="module")
def report() -> Report:
    q_table = optimal_q_table(0.6)
    exact = {str(n): 0.38 + 0.002 * n for n in range(22)}
    problems = [
        ProblemResult(id="blackjack", title="Problem 2", status="passed", score=1, max_score=1, feedback="ok",
                      measurements={"exact_curve": exact, "curve": {"12": 0.41, "20": 0.42}}),
        ProblemResult(id="cartpole", title="Problem 3", status="failed", score=0, max_score=1,
                      feedback="<script>alert(1)</script> too short",
                      measurements={"lengths": [150, 90, 200, 180]},
                      replay=_episode("CartPole-v0", cartpole_policy, 3, SHORTEST)),
        ProblemResult(id="car", title="Problem 4", status="passed", score=1, max_score=1, feedback="ok",
                      measurements={"lengths": [120, 118]},
                      replay=_episode("MountainCar-v0", mountain_car_policy, 4, "your longest")),
        ProblemResult(id="taxi", title="Problem 5", status="passed", score=1, max_score=1, feedback="ok",
                      measurements={"returned_random_mean": -770.0, "exact_random_mean": -771.09,
                                    "random_tolerance": 4.98, "returned_q_mean": 7.93, "exact_q_mean": 7.93,
                                    "q_tolerance": 0.127},
                      replay=_episode("Taxi-v4", lambda s: int(np.argmax(q_table[s])), 5, "the last")),
    ]  # fmt: skip
    return Report(
        submission="opengym.py", sha256="ab" * 32, seed=1, gymnasium_version="1.4.0", grader_version="0.1.0",
        score=3, max_score=4, problems=problems,
    )  # fmt: skip


@pytest.mark.slow
def test_every_problem_gets_its_plot_and_the_three_games_their_replay(report: Report) -> None:
    figures = all_figures(report.problems, load_config(None))
    assert {problem: [figure.mime for figure in drawn] for problem, drawn in figures.items()} == {
        "blackjack": ["image/png"],
        "cartpole": ["image/png", "image/gif"],
        "car": ["image/png", "image/gif"],
        "taxi": ["image/png", "image/gif"],
    }
    assert figures["cartpole"][1].caption.startswith("Replay of your shortest of 4 CartPole episodes: ")


@pytest.mark.parametrize("index", [1, 2, 3], ids=["cartpole", "car", "taxi"])
def test_replays_are_small_capped_animations(report: Report, index: int, tmp_path: Path) -> None:
    replay = report.problems[index].replay
    assert replay is not None
    gif, frames = replay_gif(replay)
    path = tmp_path / "replay.gif"
    path.write_bytes(gif)
    with Image.open(path) as image:
        assert image.n_frames <= frames <= MAX_GIF_FRAMES + 1  # identical frames are merged
        assert image.width <= MAX_GIF_WIDTH
    assert len(gif) < 100_000


@pytest.mark.slow
def test_the_page_is_self_contained_and_escapes_student_text(report: Report) -> None:
    page = render_html(report, load_config(None))
    assert f'content="{CSP}"' in page
    assert "<script>" not in page and "&lt;script&gt;alert(1)&lt;/script&gt;" in page
    assert "http://" not in page.replace('xmlns="http://www.w3.org', "") and "https://" not in page
    assert page.count('src="data:image/') == 7


@pytest.mark.browser
def test_chromium_renders_every_figure_under_the_page_policy(report: Report, tmp_path: Path) -> None:
    if shutil.which(CHROMIUM) is None:
        pytest.skip(f"Chromium is not installed at {CHROMIUM} (apt-get install -y chromium)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="pip install playwright")
    path = tmp_path / "report.html"
    path.write_text(render_html(report, load_config(None)), encoding="utf-8")
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"], headless=True)
        try:
            page = browser.new_page()
            console: list[str] = []
            page.on("console", lambda message: console.append(message.text))
            page.goto(path.as_uri())
            decoded = page.eval_on_selector_all(
                "figure img", "images => images.map(image => image.complete && image.naturalWidth > 0)"
            )
            styled = page.eval_on_selector("body", "body => getComputedStyle(body).maxWidth")
        finally:
            browser.close()
    assert decoded == [True] * 7
    assert styled == "832px"  # the page's own stylesheet applied: its CSP hash matches
    assert console == []


def test_the_optional_guessing_game_gets_its_counts_plotted_against_the_exact_distribution() -> None:
    result = ProblemResult(
        id="guessing_game", title="Optional: GuessingGame", status="passed", score=1, max_score=1,
        feedback="ok", measurements={"lengths": [6, 7, 7, 5, 4, 7, 6]},
    )  # fmt: skip
    [figure] = all_figures([result], load_config(None))["guessing_game"]
    assert figure.mime == "image/png" and Image.open(io.BytesIO(figure.data)).size == (480, 256)
    assert figure.caption.startswith("guessing_game(): how many guesses each of your 7 replayed games took")
