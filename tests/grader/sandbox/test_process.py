"""A child's output is kept as a terminal shows it: a line rewritten with `\\r` keeps its last state."""

from __future__ import annotations

import pytest

from grader.sandbox.process import CappedOutput


@pytest.mark.parametrize(
    ("chunks", "cap", "expected"),
    [
        pytest.param([b"plain\nlines\n"], 100, "plain\nlines\n", id="plain-lines-unchanged"),
        pytest.param([b"windows\r\nline\r\n"], 100, "windows\r\nline\r\n", id="crlf-is-a-line-end"),
        pytest.param(
            [b"windows\r", b"\nline\r", b"\n"], 100, "windows\r\nline\r\n", id="crlf-split-across-reads"
        ),
        pytest.param(
            [b"\r  0%| 0/3", b"\r 33%| 1/3", b"\r 67%| 2/3", b"\r100%| 3/3", b"\n", b"done\n"],
            100,
            "100%| 3/3\ndone\n",
            id="progress-bar-keeps-its-last-state",
        ),
        pytest.param([b"before\n\x1b[2K\rEpisode: 100\n"], 100, "before\nEpisode: 100\n", id="clear-output"),
        pytest.param([b"0123456789\n", b"abcdef"], 12, "0123456789\na\n[... 5 more", id="cap-still-holds"),
        pytest.param(
            [b"0123456789ABCDEF", b"\rlater"],
            8,
            "01234567\n[... 13 more",
            id="nothing-is-rewritten-once-dropped",
        ),
    ],
)
def test_output_is_capped_as_a_terminal_shows_it(chunks: list[bytes], cap: int, expected: str) -> None:
    output = CappedOutput(cap)
    for chunk in chunks:
        output.add(chunk)
    assert output.take().startswith(expected)
    assert output.take() == ""


def test_a_progress_bar_of_a_hundred_thousand_updates_costs_one_line() -> None:
    output = CappedOutput(65536)
    for step in range(100_000):
        output.add(f"\rtraining: {step / 1000:5.1f}%|{'#' * (step // 10_000):10}| {step}/100000".encode())
    output.add(b"\n")
    assert output.take() == f"training: {99.999:5.1f}%|{'#' * 9:10}| 99999/100000\n"
