"""The figures the lab asks for: the Blackjack win-rate plot and one rendered episode per environment.

`python -m reference.figures --out DIR` writes `blackjack_win_rate.png` and `cartpole.gif`,
`mountain_car.gif`, `taxi.gif`, `acrobot.gif`. Everything renders off-screen (matplotlib's Agg canvas,
gymnasium's `render_mode="rgb_array"`), so no display is needed.
"""

from __future__ import annotations

import argparse
import math
import os
import random
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import numpy.typing as npt
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from PIL import Image

from reference.oracles.blackjack import threshold_policy_outcome
from reference.oracles.taxi import optimal_q_table
from reference.solutions import (
    BLACKJACK_GAMES,
    CARTPOLE_ID,
    MOUNTAIN_CAR_ID,
    TAXI_ID,
    blackjack,
    cartpole_policy,
    mountain_car_policy,
)

ACROBOT_ID = "Acrobot-v1"
PLOT_THRESHOLDS = range(1, 22)
MAX_GIF_FRAMES = 150
"""Longer episodes (Acrobot's random walk lasts 500 steps) keep every k-th frame to stay under this."""

Frame = npt.NDArray[np.uint8]


@dataclass(frozen=True)
class EpisodeRecipe:
    """How to play the one episode rendered into a GIF."""

    file_name: str
    env_id: str
    policy_for: Callable[[gym.Env[Any, Any]], Callable[[Any], Any]]
    """Builds the policy (observation -> action) for the freshly made environment."""


def _random_actions(env: gym.Env[Any, Any]) -> Callable[[Any], Any]:
    return lambda _observation: env.action_space.sample()


def _greedy_on_optimal_q(_env: gym.Env[Any, Any]) -> Callable[[Any], Any]:
    greedy_actions: list[int] = np.argmax(optimal_q_table(0.6), axis=1).tolist()
    return greedy_actions.__getitem__


EPISODES = (
    EpisodeRecipe("cartpole.gif", CARTPOLE_ID, lambda _env: cartpole_policy),
    EpisodeRecipe("mountain_car.gif", MOUNTAIN_CAR_ID, lambda _env: mountain_car_policy),
    EpisodeRecipe("taxi.gif", TAXI_ID, _greedy_on_optimal_q),
    EpisodeRecipe("acrobot.gif", ACROBOT_ID, _random_actions),
)
"""The lab's renders: its CartPole and MountainCar policies, Taxi driven by a Q-table (the exact optimal
one for gamma = 0.6, which is what 100 000 episodes of `find_qvalues` approach), Acrobot at random."""


def plot_blackjack_win_rates(path: Path, *, games: int = BLACKJACK_GAMES, seed: int | None = None) -> Path:
    """Plot the win rate of "draw while the sum is <= n" for n = 1..21: exact curve and simulated points.

    Args:
        path: where to write the PNG.
        games: games simulated per n with `reference.solutions.blackjack`.
        seed: base seed of the simulations (n is added for each point).

    Returns:
        `path`.
    """
    thresholds = list(PLOT_THRESHOLDS)
    exact = [threshold_policy_outcome(n).win for n in thresholds]
    simulated = [blackjack(n, games=games, seed=None if seed is None else seed + n) for n in thresholds]
    # Where 95% of `games`-game estimates fall around the exact probability (binomial, normal approximation).
    half_widths = np.array([1.96 * math.sqrt(p * (1 - p) / games) for p in exact])

    figure = Figure(figsize=(7, 4.2), dpi=120)
    FigureCanvasAgg(figure)
    axes = figure.add_subplot()
    axes.plot(thresholds, exact, color="tab:blue", label="exact (oracle)")
    axes.fill_between(
        thresholds,
        np.array(exact) - half_widths,
        np.array(exact) + half_widths,
        color="tab:blue",
        alpha=0.15,
        label=f"95% range of a {games}-game estimate",
    )
    axes.plot(
        thresholds, simulated, "o", color="tab:orange", markersize=4, label=f"reference, {games} games each"
    )
    best = max(thresholds, key=lambda n: exact[n - 1])
    axes.annotate(
        f"best n = {best}",
        (best, exact[best - 1]),
        xytext=(best - 6, exact[best - 1] - 0.12),
        arrowprops={"arrowstyle": "->"},
    )
    axes.set(
        title="Blackjack-v0: draw while the player's sum is <= n",
        xlabel="n",
        ylabel="fraction of games won",
        xticks=thresholds,
        ylim=(-0.01, 0.5),
    )
    axes.grid(alpha=0.3)
    axes.legend(loc="lower left")
    figure.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, format="png")
    return path


def record_episode(recipe: EpisodeRecipe, *, seed: int | None = None) -> list[Frame]:
    """Play one episode with `render_mode="rgb_array"` and return its frames (first one after reset).

    Args:
        recipe: the environment and policy.
        seed: seeds the environment and its action space.

    Returns:
        One RGB frame per state visited.
    """
    # rgb_array rendering needs no window; the dummy driver keeps SDL from looking for a display.
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*is out of date", category=DeprecationWarning)
        env = gym.make(recipe.env_id, render_mode="rgb_array")
    with env:
        env.action_space.seed(seed)
        policy = recipe.policy_for(env)
        observation, _ = env.reset(seed=seed)
        frames = [_frame(env)]
        terminated = truncated = False
        while not (terminated or truncated):
            observation, _, terminated, truncated, _ = env.step(policy(observation))
            frames.append(_frame(env))
    return frames


def _frame(env: gym.Env[Any, Any]) -> Frame:
    return np.asarray(env.render(), dtype=np.uint8)


def save_gif(frames: Sequence[Frame], path: Path, *, frames_per_second: float = 30.0) -> Path:
    """Write frames as a looping animated GIF, keeping every k-th frame beyond `MAX_GIF_FRAMES`.

    Args:
        frames: RGB frames of equal size.
        path: where to write the GIF.
        frames_per_second: playback speed of the kept frames.

    Returns:
        `path`.
    """
    stride = math.ceil(len(frames) / MAX_GIF_FRAMES)
    kept = [*frames[::stride], frames[-1]] if (len(frames) - 1) % stride else list(frames[::stride])
    # One palette for the whole animation, taken from its first, middle and last frames: an order of
    # magnitude faster than Pillow's per-frame quantisation, and the colours do not flicker.
    sample = np.concatenate([kept[0], kept[len(kept) // 2], kept[-1]], axis=0)
    palette = Image.fromarray(sample).quantize(colors=255, method=Image.Quantize.FASTOCTREE)
    images = [Image.fromarray(frame).quantize(palette=palette, dither=Image.Dither.NONE) for frame in kept]
    path.parent.mkdir(parents=True, exist_ok=True)
    images[0].save(
        path,
        format="GIF",
        save_all=True,
        append_images=images[1:],
        loop=0,
        duration=round(1000 / frames_per_second),
    )
    return path


def render_episodes(out_dir: Path, *, seed: int | None = None) -> list[Path]:
    """Render one episode of CartPole, MountainCar, Taxi and Acrobot as GIFs in `out_dir`.

    Args:
        out_dir: directory for the GIFs (created if missing).
        seed: seeds every episode.

    Returns:
        The written paths.
    """
    return [save_gif(record_episode(recipe, seed=seed), out_dir / recipe.file_name) for recipe in EPISODES]


def main(argv: Sequence[str] | None = None) -> int:
    """`python -m reference.figures --out DIR [--games N] [--seed S]`."""
    parser = argparse.ArgumentParser(prog="python -m reference.figures", description=__doc__)
    parser.add_argument("--out", type=Path, required=True, help="output directory")
    parser.add_argument("--games", type=int, default=BLACKJACK_GAMES, help="games per simulated point")
    parser.add_argument("--seed", type=int, default=None, help="seed (default: fresh randomness)")
    args = parser.parse_args(argv)
    seed = random.randrange(2**31) if args.seed is None else args.seed
    written = [plot_blackjack_win_rates(args.out / "blackjack_win_rate.png", games=args.games, seed=seed)]
    written += render_episodes(args.out, seed=seed)
    for path in written:
        print(f"wrote {path} ({path.stat().st_size // 1024} KiB)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
