"""The sandbox runner (grader/sandbox/runner.py): calls, outcomes, output caps, restarts, the API.

Named test_sandbox_runner.py because tests/api/test_runner.py exists (pytest needs unique basenames).
"""

from __future__ import annotations

import textwrap
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from grader.sandbox import (
    Call,
    CallBudget,
    IsolationPolicy,
    Limits,
    OutcomeStatus,
    Sandbox,
    SandboxClosedError,
    probe_isolation,
    run_calls,
)
from grader.sandbox.child.cells import RUN_CELLS
from grader.sandbox.child.seeding import derive_call_seed
from grader.sandbox.process import CappedOutput

LIMITS = Limits(call_seconds=2, import_seconds=6, output_bytes=1024, frame_bytes=1 << 20)
SAMPLE = textwrap.dedent("""
    import os
    import random
    import signal
    import sys

    print("imported")

    def add(a, b=1):
        return a + b

    def shout(n):
        print("x" * n)
        print("to stderr", file=sys.stderr)
        return n

    def draw():
        return random.random()

    def fail():
        return 1 / 0

    def spin():
        while True:
            pass

    def segfault():
        os.kill(os.getpid(), signal.SIGSEGV)

    def abort():
        os.abort()

    def exit_with(code):
        sys.exit(code)

    def forge_header():
        for name in os.listdir("/proc/self/fd"):
            try:
                with open(f"/proc/self/fdinfo/{name}") as info:
                    flags = int(info.read().split("flags:")[1].split()[0], 8)
            except OSError:
                continue
            if int(name) > 2 and flags & os.O_ACCMODE == os.O_WRONLY:
                os.write(int(name), (2**31).to_bytes(4, "big"))
        return 0

    def huge():
        return "y" * (2 << 20)

    def resets(n):
        import gymnasium

        env = gymnasium.make("CartPole-v1")
        for _ in range(n):
            env.reset()
        return n

    not_a_function = 3
""")

pytestmark = [
    pytest.mark.sandbox,
    pytest.mark.skipif(
        not probe_isolation().full, reason="needs full isolation:\n" + probe_isolation().summary()
    ),
]


@pytest.fixture
def submission(tmp_path: Path) -> Path:
    path = tmp_path / "student.py"
    path.write_text(SAMPLE)
    return path


CLASSIFIED = [
    ("ok", Call("add", (2,), {"b": 3}), OutcomeStatus.OK, ""),
    ("exception", Call("fail"), OutcomeStatus.EXCEPTION, "fail() raised ZeroDivisionError: division by zero"),
    (
        "missing",
        Call("absent"),
        OutcomeStatus.MISSING_FUNCTION,
        "your file defines no function named `absent`",
    ),
    ("not callable", Call("not_a_function"), OutcomeStatus.MISSING_FUNCTION, "is a int, not a function"),
    (
        "signature",
        Call("add", (1, 2, 3)),
        OutcomeStatus.BAD_SIGNATURE,
        "but your function is defined as add(a, b=1)",
    ),
    ("timeout", Call("spin"), OutcomeStatus.TIMEOUT, "spin() did not return within 2 seconds"),
    ("own limit", Call("spin", seconds=1.0), OutcomeStatus.TIMEOUT, "spin() did not return within 1 seconds"),
    ("segfault", Call("segfault"), OutcomeStatus.KILLED, "segfault() was killed by SIGSEGV"),
    ("abort", Call("abort"), OutcomeStatus.KILLED, "abort() was killed by SIGABRT"),
    (
        "exit 3",
        Call("exit_with", (3,)),
        OutcomeStatus.EXITED,
        "exit_with() ended the process with exit status 3",
    ),
    (
        "forged frame header",
        Call("forge_header"),
        OutcomeStatus.INVALID_VALUE,
        "the result channel carried data the harness did not send (a frame announced 2,147,483,648 bytes",
    ),
    ("too large", Call("huge"), OutcomeStatus.OUTPUT_TOO_LARGE, "more than the limit of 1048576 bytes"),
    (
        "episode limit",
        Call("resets", (10,), budget=CallBudget(max_episodes=4, max_steps=100)),
        OutcomeStatus.EPISODE_LIMIT,
        "(it reset its environment 10 times); the grader records at most 4 resets per call of resets()",
    ),
]


@pytest.mark.parametrize(
    ("call", "status", "message"), [case[1:] for case in CLASSIFIED], ids=[case[0] for case in CLASSIFIED]
)
def test_each_way_a_call_ends_gets_its_status_and_message(
    submission: Path, call: Call, status: OutcomeStatus, message: str
) -> None:
    with Sandbox(submission, seed=1, limits=LIMITS) as sandbox:
        outcome = sandbox.call(call)
        following = sandbox.call(Call("add", (40, 2)))
    assert outcome.status is status, outcome.message
    assert message in outcome.message
    assert (following.status, following.value) == (OutcomeStatus.OK, 42)
    assert sandbox.leftovers == 0


def test_import_error_shows_the_students_traceback_only(tmp_path: Path) -> None:
    path = tmp_path / "broken.py"
    path.write_text("import math\n\ndef helper():\n    return math.nope\n\nhelper()\n")
    outcome = run_calls(path, [Call("anything")], seed=0, limits=LIMITS)[0]
    assert outcome.status is OutcomeStatus.IMPORT_ERROR
    assert "AttributeError" in outcome.message
    assert 'broken.py", line 6' in outcome.message
    assert "harness" not in outcome.message and "importlib" not in outcome.message


def test_output_is_capped_and_says_how_much_was_dropped(submission: Path) -> None:
    with Sandbox(submission, seed=1, limits=LIMITS) as sandbox:
        outcome = sandbox.call(Call("shout", (5000,)))
    assert outcome.value == 5000
    assert outcome.stdout.startswith("imported\n" + "x" * (1024 - len("imported\n")))
    assert f"{5000 + 1 + len('imported') + 1 - 1024} more bytes of output were dropped" in outcome.stdout
    assert outcome.stderr == "to stderr\n"


def test_functions_lists_signatures_from_the_ready_frame(submission: Path) -> None:
    with Sandbox(submission, seed=1, limits=LIMITS) as sandbox:
        functions = sandbox.functions
    assert [(p.name, p.kind, p.has_default) for p in functions["add"].parameters] == [
        ("a", "POSITIONAL_OR_KEYWORD", False),
        ("b", "POSITIONAL_OR_KEYWORD", True),
    ]
    assert functions["add"].is_callable
    assert not functions["not_a_function"].is_callable


def test_a_restart_after_a_fatal_outcome_does_not_change_later_calls(submission: Path) -> None:
    with_crash = run_calls(submission, [Call("draw"), Call("segfault"), Call("draw")], seed=5, limits=LIMITS)
    without = run_calls(submission, [Call("draw"), Call("add", (1,)), Call("draw")], seed=5, limits=LIMITS)
    assert with_crash[1].status is OutcomeStatus.KILLED
    assert (
        [o.seed for o in with_crash]
        == [o.seed for o in without]
        == [derive_call_seed(5, i) for i in range(3)]
    )
    assert with_crash[2].value == without[2].value
    assert with_crash[0].value != with_crash[2].value


def test_a_closed_sandbox_refuses_calls(submission: Path) -> None:
    sandbox = Sandbox(submission, seed=1, limits=LIMITS)
    sandbox.close()
    with pytest.raises(SandboxClosedError, match="closed"):
        sandbox.call(Call("add", (1,)))


def test_arguments_that_are_not_plain_data_are_refused(submission: Path) -> None:
    with (
        Sandbox(submission, seed=1, limits=LIMITS) as sandbox,
        pytest.raises(ValueError, match="not plain data"),
    ):
        sandbox.call(Call("add", (object(),)))


def test_limits_refuse_too_little_memory() -> None:
    with pytest.raises(ValueError, match=r"at least 1\.5 GiB"):
        Limits(memory_bytes=1 << 30)


def test_the_isolation_report_is_exposed(submission: Path) -> None:
    with Sandbox(submission, seed=1, limits=LIMITS, policy=IsolationPolicy.REQUIRE_FULL) as sandbox:
        assert sandbox.isolation.full
        assert [layer.name for layer in sandbox.isolation.layers] == [
            "cgroup",
            "bubblewrap",
            "seccomp",
            "privileges",
            "rlimits",
            "landlock",
        ]


CAPS = [
    ("under the cap", [b"abc"], 8, "abc"),
    ("exactly the cap", [b"abcd", b"efgh"], 8, "abcdefgh"),
    (
        "over the cap",
        [b"abcdef", b"ghij"],
        8,
        "abcdefgh\n[... 2 more bytes of output were dropped (limit 8 bytes)]\n",
    ),
    ("invalid utf-8", [b"\xff\xfe"], 8, "\ufffd\ufffd"),
]


@pytest.mark.parametrize(
    ("chunks", "cap", "text"), [case[1:] for case in CAPS], ids=[case[0] for case in CAPS]
)
def test_capped_output_keeps_the_head_and_counts_the_rest(chunks: list[bytes], cap: int, text: str) -> None:
    output = CappedOutput(cap)
    for chunk in chunks:
        output.add(chunk)
    assert output.take() == text
    assert output.take() == ""


def test_arguments_larger_than_a_pipe_buffer_reach_the_child(submission: Path) -> None:
    table = np.arange(100_000, dtype=np.float64).reshape(1000, 100)
    with Sandbox(submission, seed=1, limits=replace(LIMITS, frame_bytes=8 << 20)) as sandbox:
        outcome = sandbox.call(Call("add", (table, 1.0)))
    assert outcome.status is OutcomeStatus.OK, outcome.message
    assert np.array_equal(outcome.value, table + 1.0)


def test_a_cells_call_runs_in_the_module_globals_with_its_own_limit(tmp_path: Path) -> None:
    path = tmp_path / "gymnasium.ipynb.py"
    path.write_text("def read():\n    return table\n")

    def cells(source: str) -> tuple[list[dict[str, object]]]:
        return ([{"cell": 2, "source": source, "script": False}],)

    with Sandbox(path, seed=1, limits=LIMITS) as sandbox:
        ran = sandbox.call(Call(RUN_CELLS, cells("table = 41 + 1"), record_episodes=False))
        read = sandbox.call(Call("read"))
        failed = sandbox.call(Call(RUN_CELLS, cells("x = 1\nraise ValueError('no')"), record_episodes=False))
        slow = sandbox.call(
            Call(RUN_CELLS, cells("while True:\n    pass"), record_episodes=False, seconds=1.0)
        )
    assert (ran.status, [cell["cell"] for cell in ran.value["cells"]]) == (OutcomeStatus.OK, [2])
    assert (read.status, read.value) == (OutcomeStatus.OK, 42)
    assert failed.status is OutcomeStatus.EXCEPTION
    assert "NotebookCellError: cell 2 (line 2) raised ValueError: no" in failed.message
    assert slow.status is OutcomeStatus.TIMEOUT
    assert "did not return within 1 seconds" in slow.message
