"""One running child: its pipes read concurrently with size caps, its frames, and killing its whole tree."""

from __future__ import annotations

import atexit
import contextlib
import os
import re
import selectors
import subprocess
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import Enum

from grader.sandbox import process_model
from grader.sandbox.child.frames import HEADER
from grader.sandbox.isolation.layer import Launch
from grader.sandbox.text import clean_text

_READ_CHUNK = 1 << 16
_EXIT_GRACE_SECONDS = 2.0
_RUNNING: set[ChildProcess] = set()
"""Children not closed yet; closed at interpreter exit so that no cgroup or process outlives the grader."""


@atexit.register
def _close_running() -> None:
    for child in list(_RUNNING):
        child.close()


_CARRIAGE_RETURN = re.compile(rb"\r(?!\n)")
"""A carriage return that does not end a line: the terminal goes back to the start of the line."""


class CappedOutput:
    """Keeps the first `cap` bytes of a stream as a terminal would show them, and counts the rest.

    A line rewritten in place (`\r`, as progress bars such as tqdm and `clear_output` do thousands of
    times) keeps only its last state, so a progress bar costs one line of the cap, not the whole cap.
    """

    def __init__(self, cap: int) -> None:
        self.cap = cap
        self.head = bytearray()
        self.dropped = 0
        self._line_start = 0
        self._pending_return = False

    def add(self, data: bytes) -> None:
        """Appends `data`, keeping at most `cap` bytes in total (nothing more once anything was dropped)."""
        if self._pending_return:
            data, self._pending_return = b"\r" + data, False
        if data.endswith(b"\r"):  # "\r\n" may be split between two reads
            data, self._pending_return = data[:-1], True
        first, *rewrites = _CARRIAGE_RETURN.split(data)
        self._append(first)
        for text in rewrites:
            if not self.dropped:
                del self.head[self._line_start :]
            self._append(text)

    def _append(self, data: bytes) -> None:
        room = 0 if self.dropped else max(self.cap - len(self.head), 0)
        kept = data[:room]
        self.head += kept
        self.dropped += len(data) - len(kept)
        newline = kept.rfind(b"\n")
        if newline >= 0:
            self._line_start = len(self.head) - len(kept) + newline + 1

    def take(self) -> str:
        """The kept text (NULs replaced, a note on what was dropped), then starts afresh."""
        text = clean_text(self.head.decode("utf-8", errors="replace"), self.cap)
        if self.dropped:
            text += f"\n[... {self.dropped} more bytes of output were dropped (limit {self.cap} bytes)]\n"
        self.head = bytearray()
        self.dropped = 0
        self._line_start = 0
        self._pending_return = False
        return text


class FrameEnd(Enum):
    """Why waiting for a frame stopped."""

    FRAME = "frame"
    TIMEOUT = "timeout"
    CLOSED = "closed"
    TOO_LARGE = "too_large"
    EXTRA_DATA = "extra_data"


@dataclass
class FrameWait:
    """What `ChildProcess.wait_frame` found: the payload (FRAME) or the announced size (TOO_LARGE)."""

    end: FrameEnd
    payload: bytes = b""
    size: int = 0


@dataclass(eq=False)
class ChildProcess:
    """A started child; `stdout` and `stderr` collect its output whenever the parent waits on it."""

    launch: Launch
    process: subprocess.Popen[bytes]
    requests_fd: int
    results_fd: int
    stdout: CappedOutput
    stderr: CappedOutput
    oom_kills_at_start: int = 0
    _pending: bytearray = field(default_factory=bytearray)
    _open: dict[int, CappedOutput | None] = field(default_factory=dict)

    @classmethod
    def start(cls, make_launch: Callable[[int, int], Launch], output_bytes: int) -> ChildProcess:
        """Creates the channels, builds the command with `make_launch(requests_fd, results_fd)` and starts it.

        Raises:
            OSError: when the channels cannot be created or the command cannot start.
        """
        requests_read, requests_write = os.pipe()
        results_read, results_write = os.pipe()
        launch: Launch | None = None
        try:
            launch = make_launch(requests_read, results_write)
            process = process_model.start(
                launch.argv,
                env=launch.env,
                cwd=launch.cwd,
                channel=(requests_read, results_write),
                extra_fds=launch.pass_fds,
            )
        except BaseException:
            for descriptor in (requests_write, results_read):
                os.close(descriptor)
            if launch is not None:
                launch.cleanup()
            raise
        finally:
            os.close(requests_read)
            os.close(results_write)
        launch.close_descriptors()
        if process.stdout is None or process.stderr is None:
            raise OSError("the child's output pipes were not created")
        child = cls(
            launch,
            process,
            requests_write,
            results_read,
            CappedOutput(output_bytes),
            CappedOutput(output_bytes),
        )
        if launch.cgroup is not None:
            child.oom_kills_at_start = launch.cgroup.oom_kills()
        child._open = {
            process.stdout.fileno(): child.stdout,
            process.stderr.fileno(): child.stderr,
            results_read: None,
        }
        for descriptor in (*child._open, requests_write):
            process_model.make_nonblocking(descriptor)
        _RUNNING.add(child)
        return child

    def send(self, frame: bytes, timeout: float) -> FrameEnd:
        """Writes a request frame, reading the child's output meanwhile so that neither side blocks.

        Returns:
            FRAME once written, CLOSED when the child no longer reads requests, TIMEOUT at the deadline.
        """
        deadline = time.monotonic() + timeout
        view = memoryview(frame)
        with process_model.pipe_selector() as selector:
            selector.register(self.requests_fd, selectors.EVENT_WRITE)
            while view:
                try:
                    view = view[os.write(self.requests_fd, view) :]
                    continue
                except BlockingIOError:
                    pass
                except OSError:
                    return FrameEnd.CLOSED
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return FrameEnd.TIMEOUT
                self.drain_output()
                selector.select(min(remaining, 0.05))
        return FrameEnd.FRAME

    def wait_frame(self, timeout: float, max_frame: int) -> FrameWait:
        """Reads output and the result channel until one whole frame has arrived (or the deadline passes).

        Bytes beyond the frame already on the channel mean someone else wrote to it (EXTRA_DATA).
        """
        deadline = time.monotonic() + timeout
        with process_model.pipe_selector() as selector:
            for descriptor in self._open:
                selector.register(descriptor, selectors.EVENT_READ)
            while True:
                wait = self._frame_state(max_frame)
                if wait is not None:
                    return wait
                if self.results_fd not in self._open:
                    return FrameWait(FrameEnd.CLOSED)
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return FrameWait(FrameEnd.TIMEOUT)
                for key, _ in selector.select(remaining):
                    if not self._read(key.fd):
                        selector.unregister(key.fd)

    def _frame_state(self, max_frame: int) -> FrameWait | None:
        if len(self._pending) < HEADER.size:
            return None
        (size,) = HEADER.unpack(self._pending[: HEADER.size])
        if size > max_frame:
            return FrameWait(FrameEnd.TOO_LARGE, size=size)
        end = HEADER.size + size
        if len(self._pending) < end:
            return None
        self.drain_output()
        if len(self._pending) > end:
            return FrameWait(FrameEnd.EXTRA_DATA, size=size)
        payload = bytes(self._pending[HEADER.size : end])
        del self._pending[:end]
        return FrameWait(FrameEnd.FRAME, payload)

    def _read(self, descriptor: int) -> bool:
        """Reads what is available from one descriptor; False at end of stream."""
        data = process_model.read_available(descriptor, _READ_CHUNK)
        if data is None:
            return True
        if not data:
            self._open.pop(descriptor, None)
            return False
        sink = self._open[descriptor]
        if sink is None:
            self._pending += data
        else:
            sink.add(data)
        return True

    def drain_output(self) -> None:
        """Reads whatever the child has already written (output and result channel) without waiting."""
        for descriptor in list(self._open):
            for _ in range(4096):
                data = process_model.read_available(descriptor, _READ_CHUNK)
                if data is None:
                    break
                if not data:
                    self._open.pop(descriptor, None)
                    break
                sink = self._open[descriptor]
                if sink is None:
                    self._pending += data
                else:
                    sink.add(data)

    def wait_exit(self, timeout: float = _EXIT_GRACE_SECONDS) -> int | None:
        """Waits for the outermost process to exit, reading output meanwhile; its status or None."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            self.drain_output()
            status = self.process.poll()
            if status is not None:
                return status
            time.sleep(0.005)
        return self.process.poll()

    def reset_oom_baseline(self) -> None:
        """Counts OOM kills from now on (called when a call starts)."""
        if self.launch.cgroup is not None:
            self.oom_kills_at_start = self.launch.cgroup.oom_kills()

    def oom_killed(self) -> bool:
        """Whether the kernel killed a process of this child's cgroup for exceeding its memory limit."""
        cgroup = self.launch.cgroup
        return cgroup is not None and cgroup.oom_kills() > self.oom_kills_at_start

    def kill_tree(self) -> None:
        """Kills the whole tree: the cgroup, the outermost process (bwrap takes its PID namespace down with
        it), and what `process_model.end` ends on this system (its process group on POSIX)."""
        if self.launch.cgroup is not None:
            self.launch.cgroup.kill()
        process_model.end(self.process)

    def close(self) -> bool:
        """Ends the child (EOF on its requests, then SIGKILL) and releases everything; False if a process
        of its tree could not be removed."""
        _RUNNING.discard(self)
        with contextlib.suppress(OSError):
            os.close(self.requests_fd)
        if self.process.poll() is None and self.wait_exit(0.5) is None:
            self.kill_tree()
        self.kill_tree_leftovers()
        with contextlib.suppress(subprocess.TimeoutExpired):
            self.process.wait(timeout=_EXIT_GRACE_SECONDS)
        for stream in (self.process.stdout, self.process.stderr):
            if stream is not None:
                stream.close()
        with contextlib.suppress(OSError):
            os.close(self.results_fd)
        return self.launch.cleanup()

    def kill_tree_leftovers(self) -> None:
        """Kills processes the child left behind after its main process exited (daemons)."""
        if self.launch.cgroup is not None:
            self.launch.cgroup.kill()
