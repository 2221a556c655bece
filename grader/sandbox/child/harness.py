"""The child harness: prepare the process, import the submission, then serve call requests.

Started by the sandbox runner (see `grader.sandbox.child.__main__` for the command line). Results go
to the results fd as frames (`frames.py`); the student's prints go to fds 1 and 2 unchanged.
"""

from __future__ import annotations

import argparse
import importlib.abc
import importlib.machinery
import os
import sys
from collections.abc import Sequence
from importlib.machinery import ModuleSpec
from pathlib import Path
from types import ModuleType
from typing import Any

import grader.compat
from grader.compat.dialect import show_file_as
from grader.sandbox.child import frames
from grader.sandbox.child.calls import parse_call, run_call
from grader.sandbox.child.errors import ProtocolError
from grader.sandbox.child.importer import ImportFailure, function_table, import_submission
from grader.sandbox.child.light_ipython import LightIPython
from grader.sandbox.child.recorder import DEFAULT_MAX_RECORDED_STEPS, Recorder, install

EXIT_PROTOCOL_ERROR = 70
"""Exit status when the runner sent a frame the harness cannot parse (EX_SOFTWARE)."""


def parse_arguments(argv: Sequence[str]) -> argparse.Namespace:
    """Parse the child's command line (documented in `grader.sandbox.child.__main__`)."""
    parser = argparse.ArgumentParser(prog="grader.sandbox.child")
    parser.add_argument("--submission", type=Path, required=True)
    parser.add_argument("--requests", type=int, required=True, help="fd carrying call frames from the runner")
    parser.add_argument("--results", type=int, required=True, help="fd carrying result frames to the runner")
    parser.add_argument(
        "--handles", action="store_true", help="--requests and --results are Windows handles, not fds"
    )
    parser.add_argument("--max-frame", type=int, default=frames.DEFAULT_MAX_FRAME)
    parser.add_argument(
        "--seed", type=int, default=0, help="seeds randomness while the submission is imported"
    )
    parser.add_argument("--max-recorded-steps", type=int, default=DEFAULT_MAX_RECORDED_STEPS)
    parser.add_argument(
        "--name", default=None, help="the file's own name in messages (the submission's file name by default)"
    )
    return parser.parse_args(argv)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the harness; returns the process exit status (0 after the runner closes the request fd)."""
    arguments = parse_arguments(sys.argv[1:] if argv is None else argv)
    if arguments.handles:
        _descriptors_from_handles(arguments)
    for fd in (arguments.requests, arguments.results):
        os.set_inheritable(fd, False)
    requests = os.fdopen(arguments.requests, "rb")
    submission: Path = arguments.submission
    prepare_process(submission)
    if arguments.name:
        show_file_as(str(submission), arguments.name)
    recorder = Recorder(arguments.seed, arguments.max_recorded_steps)
    install(recorder)
    recorder.begin_import(arguments.seed)
    loaded = import_submission(submission, arguments.name)
    recorder.finish_import(vars(loaded) if isinstance(loaded, ModuleType) else {})
    _flush_student_output()
    if isinstance(loaded, ImportFailure):
        _send(arguments, {"type": "import_error", "message": loaded.message, "traceback": loaded.traceback})
        return 0
    _send(arguments, {"type": "ready", "functions": function_table(loaded)})
    return _serve(loaded, requests, recorder, arguments)


def _descriptors_from_handles(arguments: argparse.Namespace) -> None:
    """Turns the inherited Windows handles of the two pipes into descriptors (the runner names handles
    where descriptors cannot be passed: `grader.sandbox.process_model`)."""
    import msvcrt

    arguments.requests = msvcrt.open_osfhandle(arguments.requests, os.O_RDONLY)  # type: ignore[attr-defined,unused-ignore]
    arguments.results = msvcrt.open_osfhandle(arguments.results, os.O_WRONLY)  # type: ignore[attr-defined,unused-ignore]


def prepare_process(submission: Path) -> None:
    """Make the process look like `python submission.py` with the compat layer and no display (IPython's
    display calls served without loading IPython: `light_ipython`)."""
    grader.compat.activate()
    sys.path.insert(1, str(submission.resolve().parent))
    sys.argv = [str(submission)]
    sys.meta_path.insert(0, _QuietPyplot())
    sys.meta_path.insert(0, LightIPython())


def _serve(module: ModuleType, requests: Any, recorder: Recorder, arguments: argparse.Namespace) -> int:
    while True:
        try:
            frame = frames.read_frame(requests, arguments.max_frame)
            if frame is None:
                return 0
            request = parse_call(frame)
        except ProtocolError as error:
            os.write(2, f"gymgrade harness: bad request: {error}\n".encode())
            return EXIT_PROTOCOL_ERROR
        payload = run_call(
            module, request, recorder, arguments.submission, arguments.max_frame, arguments.name
        )
        _flush_student_output()
        _write_all(arguments.results, frames.HEADER.pack(len(payload)) + payload)


def _send(arguments: argparse.Namespace, message: dict[str, Any]) -> None:
    _write_all(arguments.results, frames.encode_frame(message, arguments.max_frame))


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view) :]


def _flush_student_output() -> None:
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError, AttributeError):
            continue


def _no_display(*args: Any, **kwargs: Any) -> None:
    """Stands in for `pyplot.show` and `pyplot.pause`: there is no display in the sandbox."""


class _QuietPyplot(importlib.abc.MetaPathFinder):
    """Makes `matplotlib.pyplot.show()` and `pause()` return at once, whatever backend is chosen."""

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> ModuleSpec | None:
        if fullname != "matplotlib.pyplot":
            return None
        spec = importlib.machinery.PathFinder.find_spec(fullname, path)
        if spec is None or spec.loader is None or not hasattr(spec.loader, "exec_module"):
            return spec
        loader = spec.loader
        original_exec_module = loader.exec_module

        def exec_module(module: ModuleType) -> None:
            original_exec_module(module)
            module.show = _no_display  # type: ignore[attr-defined]
            module.pause = _no_display  # type: ignore[attr-defined]

        loader.exec_module = exec_module  # type: ignore[method-assign]
        return spec
