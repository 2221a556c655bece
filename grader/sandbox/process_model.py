"""How a sandbox child is started, read and ended on this system: the one place that decides it.

Three models, chosen once from `grader.sandbox.host.HOST`:

- **posix** (Linux, macOS): the request and result pipes reach the child by descriptor number
  (`pass_fds`, with the layers' own descriptors), the child leads a new session, and ending it SIGKILLs
  its process group (a cgroup, when that layer is active, takes the rest of its tree). Pipes are read
  without blocking, waited on with `selectors`.
- **windows**: the pipes reach the child as inheritable handles named on its command line (`--handles`;
  `subprocess.STARTUPINFO`'s handle list gives it exactly those), and ending it is `Popen.kill()`
  (TerminateProcess). `select` waits on sockets only there, so pipes are polled with PeekNamedPipe and
  read only as far as they hold data; requests are written blocking (they go to a child waiting for
  them). Processes the child started itself are not ended with it.
- **inherited**: a system that has neither (a Python without `fork` and `pass_fds` that is not Windows):
  the pipes are made inheritable and every inheritable descriptor is kept (`close_fds=False`); ended with
  `Popen.kill()`. The project's tests use it to run the check under a Windows-shaped Python.

No model needs a layer: a child with no isolation layer active starts, is bounded by the wall-clock
limit of each call and is ended on every system.
"""

from __future__ import annotations

import contextlib
import os
import selectors
import subprocess
import time
from collections.abc import Mapping, Sequence
from types import TracebackType
from typing import Any

from grader.sandbox import signalling
from grader.sandbox.host import HOST, Feature

if HOST.has(Feature.POSIX_PROCESSES):
    MODEL = "posix"
elif HOST.has(Feature.WINDOWS_HANDLES):
    MODEL = "windows"
else:
    MODEL = "inherited"
_WINDOWS_ENVIRONMENT = ("SYSTEMROOT", "WINDIR", "COMSPEC", "PATHEXT", "PATH")
"""Variables a Windows process needs whatever else its environment holds: the system's folders (sockets,
random numbers) and PATH, where a conda Python finds the DLLs of numpy's libraries."""
_POLL_SECONDS = 0.002
_QUERY_LIMITED_INFORMATION = 0x1000
_STILL_ACTIVE = 259


def channel_arguments(requests_fd: int, results_fd: int) -> list[str]:
    """The harness's arguments naming its request and result pipes as the child will see them."""
    if MODEL == "windows":
        import msvcrt

        handles = [msvcrt.get_osfhandle(fd) for fd in (requests_fd, results_fd)]  # type: ignore[attr-defined,unused-ignore]
        return ["--requests", str(handles[0]), "--results", str(handles[1]), "--handles"]
    return ["--requests", str(requests_fd), "--results", str(results_fd)]


def system_environment() -> dict[str, str]:
    """What the child's cleared environment must keep of this process's on this system."""
    if MODEL != "windows":
        return {}
    return {name: os.environ[name] for name in _WINDOWS_ENVIRONMENT if name in os.environ}


def start(
    argv: Sequence[str],
    *,
    env: Mapping[str, str],
    cwd: str | None,
    channel: Sequence[int],
    extra_fds: Sequence[int],
) -> subprocess.Popen[bytes]:
    """Starts the child with `channel` (its ends of the two pipes) and `extra_fds` inherited.

    Raises:
        OSError: when the command cannot start, or descriptors besides the channel must be passed on a
            system that cannot pass them.
    """
    options: dict[str, Any] = {}
    if MODEL == "posix":
        options = {"pass_fds": (*channel, *extra_fds), "start_new_session": True, "close_fds": True}
    elif extra_fds:
        raise OSError(f"this system ({HOST.system}) cannot pass the descriptors {list(extra_fds)} to a child")
    elif MODEL == "windows":
        import msvcrt

        handles = [msvcrt.get_osfhandle(fd) for fd in channel]  # type: ignore[attr-defined,unused-ignore]
        for handle in handles:
            os.set_handle_inheritable(handle, True)  # type: ignore[attr-defined,unused-ignore]
        options = {
            "startupinfo": subprocess.STARTUPINFO(lpAttributeList={"handle_list": handles}),  # type: ignore[attr-defined,unused-ignore]
            "creationflags": subprocess.CREATE_NEW_PROCESS_GROUP | subprocess.CREATE_NO_WINDOW,  # type: ignore[attr-defined,unused-ignore]
            "close_fds": True,
        }
    else:
        for fd in channel:
            os.set_inheritable(fd, True)
        options = {"close_fds": False}
    return subprocess.Popen(
        list(argv),
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=dict(env),
        cwd=cwd,
        **options,
    )


def end(process: subprocess.Popen[bytes]) -> None:
    """Kills the child at once: its process group where there is one (never the grader's own:
    `signalling.refusal`), else the process itself."""
    if process.returncode is not None:  # reaped: its pid and group id may belong to someone else now
        return
    if MODEL == "posix":
        signalling.kill_group(process.pid)
    with contextlib.suppress(ProcessLookupError, PermissionError):
        process.kill()


def exists(pid: int) -> bool | None:
    """Whether a process `pid` is running; None when this process may not ask (another user's).

    Windows' `os.kill(pid, 0)` would end the process (TerminateProcess with exit code 0), so there it is
    asked with OpenProcess and GetExitCodeProcess.
    """
    if MODEL == "windows":
        import _winapi

        try:
            handle = _winapi.OpenProcess(_QUERY_LIMITED_INFORMATION, False, pid)  # type: ignore[attr-defined,unused-ignore]
        except PermissionError:
            return None
        except OSError:
            return False
        try:
            return bool(_winapi.GetExitCodeProcess(handle) == _STILL_ACTIVE)  # type: ignore[attr-defined,unused-ignore]
        finally:
            _winapi.CloseHandle(handle)  # type: ignore[attr-defined,unused-ignore]
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return None
    return True


def make_nonblocking(fd: int) -> None:
    """Lets `read_available` and writes on `fd` return at once (Windows pipes are polled instead)."""
    if MODEL != "windows":
        os.set_blocking(fd, False)


def read_available(fd: int, size: int) -> bytes | None:
    """Up to `size` bytes the pipe holds now; b"" at its end; None when it holds nothing yet."""
    if MODEL == "windows":
        try:
            available = _peek(fd)
        except OSError:  # the writer closed its end: nothing more will come
            return b""
        return os.read(fd, min(available, size)) if available else None
    try:
        return os.read(fd, size)
    except BlockingIOError:
        return None


# The Windows-only calls below carry `type: ignore`: mypy checks this module as Linux sees it.
def _peek(fd: int) -> int:
    import _winapi
    import msvcrt

    available: int = _winapi.PeekNamedPipe(msvcrt.get_osfhandle(fd), 0)[0]  # type: ignore[attr-defined,unused-ignore]
    return available


class _PollingSelector:
    """The part of `selectors.BaseSelector` the child's pipes use, for Windows, where `select` waits on
    sockets only: a pipe is ready to read when PeekNamedPipe shows data or its end; writes are blocking."""

    def __init__(self) -> None:
        self._keys: dict[int, selectors.SelectorKey] = {}

    def register(self, fd: int, events: int) -> None:
        self._keys[fd] = selectors.SelectorKey(fd, fd, events, None)

    def unregister(self, fd: int) -> None:
        self._keys.pop(fd, None)

    def select(self, timeout: float | None = None) -> list[tuple[selectors.SelectorKey, int]]:
        deadline = time.monotonic() + (timeout if timeout is not None else float("inf"))
        while True:
            ready = [(key, key.events) for key in self._keys.values() if self._ready(key)]
            if ready or time.monotonic() >= deadline:
                return ready
            time.sleep(_POLL_SECONDS)

    @staticmethod
    def _ready(key: selectors.SelectorKey) -> bool:
        if key.events & selectors.EVENT_WRITE:
            return True
        try:
            return _peek(key.fd) > 0
        except OSError:
            return True

    def __enter__(self) -> _PollingSelector:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None
    ) -> None:
        self._keys.clear()


def pipe_selector() -> selectors.BaseSelector | _PollingSelector:
    """A selector over the child's pipes on this system."""
    return _PollingSelector() if MODEL == "windows" else selectors.DefaultSelector()
