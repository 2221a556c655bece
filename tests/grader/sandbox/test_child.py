"""The child harness run in a plain subprocess (no isolation): import, call outcomes, process setup."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from collections.abc import Iterator
from pathlib import Path

import pytest
from child_client import ChildClient, write_submission

from grader.sandbox.child.frames import decode_value

pytestmark = pytest.mark.slow  # starts the child harness as a process, one per test in part

ROOT = Path(__file__).resolve().parents[3]

STUDENT = textwrap.dedent("""
    import os
    import sys
    import time

    import gym
    import matplotlib.pyplot as plt
    import numpy as np
    from IPython.display import clear_output

    TABLE = {"a": 1}


    class RiggedFloat(float):
        def __eq__(self, other):
            return True

        def __ge__(self, other):
            return True

        __hash__ = float.__hash__


    def add(a, b=2):
        return a + b


    def rigged():
        return RiggedFloat(0.9)


    def span(seconds):
        entered = time.perf_counter()
        time.sleep(seconds)
        return [entered, time.perf_counter()]


    def objects():
        return np.array([1, None], dtype=object)


    def fails():
        return helper(0)


    def helper(value):
        return 1 / value


    def out_of_memory():
        raise MemoryError


    def environment():
        plt.plot([1, 2])
        plt.show()
        clear_output(wait=True)
        names = ("MPLBACKEND", "OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")
        return {name: os.environ.get(name) for name in names}


    def forge():
        print('\\x00\\x00\\x00\\x10{"type":"result"}', flush=True)
        sys.stdout.write("PASSED\\n")
        return 0.1


    def array_result():
        return np.arange(6, dtype=np.float32).reshape(2, 3)


    def big_array():
        return np.zeros(100_000)


    def long_text():
        return ["x" * 3000] * 5


    def exits():
        sys.exit(3)


    class Stop(BaseException):
        pass


    def base_exception():
        raise Stop("stop")


    def interrupted():
        raise KeyboardInterrupt


    def long_message():
        raise ValueError("x" * 100_000)


    class Opaque:
        @property
        def __signature__(self):
            raise RuntimeError("no signature")

        def __call__(self):
            return 5


    opaque = Opaque()


    if __name__ == "__main__":
        print("main block ran")
""")


@pytest.fixture(scope="module")
def child(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ChildClient]:
    submission = write_submission(tmp_path_factory.mktemp("child"), STUDENT)
    with ChildClient(submission) as client:
        yield client


def test_ready_frame_lists_public_names_with_parameters(child: ChildClient) -> None:
    ready = child.first_frame

    assert ready is not None and ready["type"] == "ready"
    assert ready["functions"]["add"] == {
        "parameters": [
            {"name": "a", "kind": "POSITIONAL_OR_KEYWORD", "has_default": False},
            {"name": "b", "kind": "POSITIONAL_OR_KEYWORD", "has_default": True},
        ],
        "is_callable": True,
    }
    assert ready["functions"]["TABLE"] == {"parameters": [], "is_callable": False}
    assert "np" not in ready["functions"]


def test_main_block_does_not_run(child: ChildClient) -> None:
    assert child.call("add", 1)  # the child has imported and served a call
    assert "main block ran" not in child.output()[0]


CALLS = [
    ("add", (1,), {}, "ok", ""),
    ("add", (), {"a": 1, "b": 5}, "ok", ""),
    (
        "add",
        (1, 2, 3),
        {},
        "bad_signature",
        "the grader calls add(1, 2, 3) but your function is defined as add(a, b=2) (too many positional "
        "arguments); change its parameters to accept that call",
    ),
    ("add", (), {"c": 1}, "bad_signature", "(missing a required argument: 'a')"),
    (
        "missing",
        (),
        {},
        "missing_function",
        "your file defines no function named `missing`; define `def missing(...):` at the top level of the "
        'file (not inside another function or an `if __name__ == "__main__":` block)',
    ),
    ("TABLE", (), {}, "missing_function", "`TABLE` in your file is a dict, not a function"),
    ("rigged", (), {}, "invalid_value", "found submission.RiggedFloat, a subclass of float"),
    ("objects", (), {}, "invalid_value", "numpy array of dtype object"),
    ("fails", (), {}, "exception", "fails() raised ZeroDivisionError: division by zero"),
    ("out_of_memory", (), {}, "memory_limit", "out_of_memory() ran out of memory"),
    ("base_exception", (), {}, "exception", "base_exception() raised submission.Stop: stop"),
    ("interrupted", (), {}, "exception", "interrupted() raised KeyboardInterrupt"),
    ("long_message", (), {}, "exception", "characters left out"),
    ("opaque", (), {}, "ok", ""),
]


@pytest.mark.parametrize(
    ("function", "args", "kwargs", "status", "message"),
    CALLS,
    ids=[f"{call[0]}-{call[3]}-{index}" for index, call in enumerate(CALLS)],
)
def test_call_outcomes(
    child: ChildClient,
    function: str,
    args: tuple[object, ...],
    kwargs: dict[str, object],
    status: str,
    message: str,
) -> None:
    result = child.call(function, *args, **kwargs)

    assert result is not None
    assert result["status"] == status, result["message"]
    assert message in result["message"]
    assert (result["value"] is None) == (status != "ok")


def test_exception_traceback_shows_only_the_students_frames(child: ChildClient) -> None:
    result = child.call("fails")

    assert result is not None
    traceback = result["traceback"]
    assert traceback.startswith("Traceback (most recent call last):")
    assert "in fails" in traceback and "in helper" in traceback
    assert "grader" not in traceback and "calls.py" not in traceback


def test_matplotlib_ipython_and_thread_settings(child: ChildClient) -> None:
    result = child.call("environment")

    assert result is not None and result["status"] == "ok", result["message"]
    assert result["value"] == {"MPLBACKEND": "Agg", "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    assert "non-interactive" not in child.output()[1]


def test_printed_frames_and_verdicts_stay_in_the_students_output(child: ChildClient) -> None:
    result = child.call("forge")

    assert result is not None and result["status"] == "ok"
    assert result["value"] == 0.1
    assert "PASSED" in child.output()[0]


def test_arrays_come_back_as_arrays(child: ChildClient) -> None:
    result = child.call("array_result")

    assert result is not None
    assert decode_value(result["value"]).tolist() == [[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]]


def test_wall_time_is_measured_around_each_call(child: ChildClient) -> None:
    # Events, not a clock threshold: `span` reads the child's clock as it is entered and as it returns, so a
    # wall time measured around the call holds that span, on any machine under any load. The clock moved
    # over its pause, so a constant, or a time taken after the call returned, fails.
    quick = child.call("add", 1)
    assert quick is not None
    assert isinstance(quick["wall_time"], float) and quick["wall_time"] >= 0
    paused = child.call("span", 0.01)
    assert paused is not None and paused["status"] == "ok", paused
    entered, returning = decode_value(paused["value"])
    assert returning > entered  # the clock moved over the pause
    assert paused["wall_time"] >= returning - entered


@pytest.mark.parametrize(
    ("function", "message"),
    [
        ("big_array", "big_array() returned about 1066666 bytes of data, more than the limit of 10000 bytes"),
        ("long_text", "long_text() returned about 12000 bytes of data, more than the limit of 10000 bytes"),
    ],
    ids=["array", "strings"],
)
def test_results_over_the_frame_limit_are_output_too_large(
    tmp_path: Path, function: str, message: str
) -> None:
    with ChildClient(write_submission(tmp_path, STUDENT), extra_args=("--max-frame", "10000")) as client:
        result = client.call(function)

    assert result is not None and result["status"] == "output_too_large"
    assert result["message"] == f"{message}; return less data"


def test_sys_exit_in_a_call_ends_the_child_without_a_result(tmp_path: Path) -> None:
    with ChildClient(write_submission(tmp_path, STUDENT)) as client:
        assert client.call("exits") is None
        assert client.process.wait(timeout=30) == 3


IMPORT_FAILURES = [
    (
        "def broken(:\n    pass\n",
        "submission.py is not valid Python: invalid syntax (line 1)",
        ["def broken(:", "^", "SyntaxError"],
    ),
    (
        "import os\n\nvalue = 1\nraise RuntimeError('boom at import')\n",
        "importing submission.py raised RuntimeError: boom at import",
        ['submission.py", line 4, in <module>', "RuntimeError: boom at import"],
    ),
    (
        "import numpy_but_misspelled\n",
        "importing submission.py raised ModuleNotFoundError: No module named 'numpy_but_misspelled'; "
        "the grader has no module `numpy_but_misspelled`: use the packages your course provides, or ask your "
        "instructor to add it; instructors install the package into the grader's Python",
        ["line 1, in <module>", "No module named 'numpy_but_misspelled'"],
    ),
]


@pytest.mark.parametrize(
    ("source", "message", "traceback_parts"), IMPORT_FAILURES, ids=["syntax", "exception", "missing-module"]
)
def test_import_errors_report_the_students_traceback_only(
    tmp_path: Path, source: str, message: str, traceback_parts: list[str]
) -> None:
    with ChildClient(write_submission(tmp_path, source)) as client:
        frame = client.first_frame

        assert frame is not None and frame["type"] == "import_error"
        assert frame["message"].startswith(message)
        for part in traceback_parts:
            assert part in frame["traceback"]
        assert "importlib" not in frame["traceback"] and "grader" not in frame["traceback"]
        assert client.close() == 0


@pytest.mark.parametrize(
    ("source", "message"),
    [
        (
            "def broken(:\n    pass\n",
            "smithjohn_1_2_opengym-1.py is not valid Python: invalid syntax (line 1)",
        ),
        ("raise RuntimeError('boom')\n", "importing smithjohn_1_2_opengym-1.py raised RuntimeError: boom"),
    ],
    ids=["syntax", "exception"],
)
def test_import_errors_name_the_file_by_the_name_it_is_shown_by(
    tmp_path: Path, source: str, message: str
) -> None:
    """A class's zip is graded from numbered copies: ``--name`` is what the messages call the file."""
    arguments = ("--name", "smithjohn_1_2_opengym-1.py")
    with ChildClient(write_submission(tmp_path, source), extra_args=arguments) as client:
        frame = client.first_frame

        assert frame is not None and frame["type"] == "import_error"
        assert frame["message"] == message


NAMED = textwrap.dedent("""
    import gym


    def fails():
        raise ValueError("no games today")


    def steps():
        env = gym.make("CartPole-v1")
        env.reset()
        obs, reward, done, info = env.step(0)
        return int(done)
""")


def test_calls_name_the_file_by_the_name_it_is_shown_by(tmp_path: Path) -> None:
    """A call's traceback and the compat layer's events name the file as ``--name`` does, never its copy."""
    shown = "smithjohn_1_2_opengym-1.py"
    with ChildClient(write_submission(tmp_path, NAMED, name="0.py"), extra_args=("--name", shown)) as client:
        assert client.first_frame is not None and client.first_frame["type"] == "ready"
        failed = client.call("fails")
        stepped = client.call("steps")

    assert failed is not None and stepped is not None
    assert f'File "{tmp_path}/{shown}", line 6, in fails' in failed["traceback"]
    details = " ".join(str(event["detail"]) for event in stepped["compat_events"])
    assert f"steps() in {shown} was served the classic gym API" in details
    assert "0.py" not in failed["traceback"] + details


def test_lab_only_ids_and_clear_output_work_at_import(tmp_path: Path) -> None:
    source = "import gym\nfrom IPython.display import clear_output\nenv = gym.make('NChain-v0')\n"

    with ChildClient(write_submission(tmp_path, source)) as client:
        assert client.first_frame is not None and client.first_frame["type"] == "ready"


def test_the_child_harness_imports_none_of_the_parents_modules() -> None:
    # grader.sandbox's public names load lazily, so a child (one per problem) starts without pydantic,
    # the runner, the replay or the isolation layers.
    parent_only = ["pydantic", "grader.sandbox.runner", "grader.sandbox.replay", "grader.sandbox.episode_log"]
    program = (
        f"import sys, grader.sandbox.child.harness; print([m for m in {parent_only!r} if m in sys.modules])"
    )
    found = subprocess.run(
        [sys.executable, "-I", "-c", f"import sys; sys.path.insert(0, {str(ROOT)!r}); {program}"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()

    assert found == "[]"
