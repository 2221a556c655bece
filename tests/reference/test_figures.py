"""Tests for reference/figures.py: the plot and the GIFs are written as valid images, headless."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from reference.figures import EPISODES, main, plot_blackjack_win_rates, record_episode, save_gif


def test_blackjack_plot_is_a_png(tmp_path: Path, seed: int) -> None:
    path = plot_blackjack_win_rates(tmp_path / "nested" / "plot.png", games=50, seed=seed)
    with Image.open(path) as image:
        assert image.format == "PNG"
        assert image.size == (840, 504)


def test_episode_renders_to_an_animated_gif(tmp_path: Path, seed: int) -> None:
    recipe = next(recipe for recipe in EPISODES if recipe.env_id == "Taxi-v4")
    frames = record_episode(recipe, seed=seed)
    assert len(frames) >= 2
    assert len({frame.shape for frame in frames}) == 1
    path = save_gif(frames, tmp_path / recipe.file_name)
    with Image.open(path) as image:
        assert image.format == "GIF"
        assert image.size == (frames[0].shape[1], frames[0].shape[0])
        assert getattr(image, "n_frames", 1) > 1


def test_long_episodes_are_thinned_but_keep_the_last_frame(tmp_path: Path) -> None:
    # 401 distinct frames (a moving bar); the GIF keeps every 3rd and the final one.
    frames = [np.zeros((8, 401, 3), dtype=np.uint8) for _ in range(401)]
    for index, frame in enumerate(frames):
        frame[:, index] = 255
    with Image.open(save_gif(frames, tmp_path / "long.gif")) as image:
        assert image.n_frames == 135
        image.seek(image.n_frames - 1)
        assert np.asarray(image.convert("RGB"))[0, 400].tolist() == [255, 255, 255]


@pytest.mark.slow  # plays and draws every figure
def test_command_writes_all_figures(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--out", str(tmp_path), "--games", "20", "--seed", "3"]) == 0
    names = sorted(path.name for path in tmp_path.iterdir())
    assert names == ["acrobot.gif", "blackjack_win_rate.png", "cartpole.gif", "mountain_car.gif", "taxi.gif"]
    assert capsys.readouterr().out.count("wrote ") == 5
    for name in names:
        with Image.open(tmp_path / name) as image:
            assert image.format == ("PNG" if name.endswith(".png") else "GIF")
            assert name.endswith(".png") or image.n_frames > 1
