"""Student code imports the course's packages inside the full sandbox; bars and plots stay harmless."""

from __future__ import annotations

import textwrap
from collections.abc import Iterator

import pytest

from grader.lab.assignment import STUDENT_MODULES
from grader.sandbox import Call, IsolationPolicy, Limits, OutcomeStatus, Sandbox

SUBMISSION = textwrap.dedent(
    """
    import matplotlib.pyplot as plt
    import pandas as pd
    import scipy.stats as st
    from IPython.display import clear_output, display
    from tqdm.auto import tqdm, trange


    def versions():
        import importlib
        return {{name: importlib.import_module(name).__version__ for name in {packages!r}}}


    def train(n):
        total = 0
        for step in tqdm(range(n), desc="training"):
            total += step
        for episode in trange(3, desc="episodes", leave=False):
            clear_output(wait=True)
            print("Episode:", episode)
        return total


    def plot_and_summarise(n):
        frame = pd.DataFrame({{"n": range(n), "win": [i % 3 == 0 for i in range(n)]}})
        display(frame.describe())
        plt.plot(frame["n"], frame["win"].cumsum())
        plt.title("wins")
        plt.savefig("wins.png")
        plt.show()
        test = st.binomtest(int(frame["win"].sum()), n, 1 / 3)
        return [plt.get_backend().lower(), round(float(frame["win"].mean()), 4), test.pvalue > 0.01]
    """
).format(packages=STUDENT_MODULES)


@pytest.fixture(scope="module")
def sandbox(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Sandbox]:
    path = tmp_path_factory.mktemp("students") / "opengym.py"
    path.write_text(SUBMISSION)
    limits = Limits(call_seconds=60, import_seconds=60, output_bytes=4096)
    with Sandbox(path, seed=0, policy=IsolationPolicy.REQUIRE_FULL, limits=limits) as opened:
        yield opened


@pytest.mark.sandbox
def test_every_student_package_imports_in_the_full_sandbox(sandbox: Sandbox) -> None:
    outcome = sandbox.call(Call("versions", (), record_episodes=False))
    assert outcome.status is OutcomeStatus.OK, outcome.message
    assert isinstance(outcome.value, dict) and sorted(outcome.value) == sorted(STUDENT_MODULES)
    # The file's import of pyplot built matplotlib's font list: fc-list read /etc/fonts, printing nothing.
    assert "Fontconfig" not in outcome.stderr, outcome.stderr


@pytest.mark.sandbox
def test_a_progress_bar_of_a_long_loop_leaves_its_final_line_only(sandbox: Sandbox) -> None:
    outcome = sandbox.call(Call("train", (200_000,), record_episodes=False))
    assert (outcome.status, outcome.value) == (OutcomeStatus.OK, sum(range(200_000)))
    bar_lines = [line for line in outcome.stderr.splitlines() if line.startswith("training:")]
    assert len(bar_lines) == 1 and "100%" in bar_lines[0] and "200000/200000" in bar_lines[0]
    assert "dropped" not in outcome.stderr + outcome.stdout
    assert outcome.stdout.strip().splitlines()[-1] == "Episode: 2"


@pytest.mark.sandbox
def test_plots_draw_off_screen_and_show_is_harmless(sandbox: Sandbox) -> None:
    outcome = sandbox.call(Call("plot_and_summarise", (300,), record_episodes=False))
    assert outcome.status is OutcomeStatus.OK, outcome.message
    assert outcome.value == ["agg", 0.3333, True]
