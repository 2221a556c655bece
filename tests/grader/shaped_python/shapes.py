"""What a shaped interpreter takes away from this Linux CPython before anything else runs.

`windows`: what Windows' CPython lacks (the POSIX-only modules, `fork`, sessions and process groups,
the uid and gid calls, CPU affinity, every signal Windows does not have and the interval timers) and how
its `subprocess.Popen` differs (it refuses `preexec_fn` and `pass_fds` and ignores
`start_new_session`); text opened without an encoding and the standard streams use cp1252, Windows'
usual ANSI code page.

`macos`: what a student's Mac looks like to the grader: the platform is "darwin" (no /proc, cgroups,
namespaces, seccomp or Landlock for the grader to use), no `sched_getaffinity`, an unprivileged user.
"""

from __future__ import annotations

import builtins
import io
import os
import signal
import subprocess
import sys
import sysconfig
from collections.abc import Callable
from typing import Any

WINDOWS_MISSING_MODULES = ("resource", "pwd", "grp", "fcntl", "termios", "pty", "tty", "posix_spawn")
WINDOWS_MISSING_OS = (
    "fork",
    "forkpty",
    "killpg",
    "setsid",
    "getsid",
    "setpgid",
    "getpgid",
    "getpgrp",
    "setpgrp",
    "getuid",
    "geteuid",
    "getgid",
    "getegid",
    "getgroups",
    "setuid",
    "seteuid",
    "setgid",
    "setegid",
    "setgroups",
    "setreuid",
    "setregid",
    "getresuid",
    "getresgid",
    "setresuid",
    "setresgid",
    "initgroups",
    "sched_getaffinity",
    "sched_setaffinity",
    "register_at_fork",
    "posix_spawn",
    "posix_spawnp",
)
WINDOWS_SIGNALS = {"SIGABRT", "SIGFPE", "SIGILL", "SIGINT", "SIGSEGV", "SIGTERM"}
"""The signals Windows' `signal` module has (besides SIGBREAK and the CTRL events)."""
WINDOWS_MISSING_SIGNAL_CALLS = ("alarm", "setitimer", "getitimer", "pause", "siginterrupt", "pthread_kill")
ANSI_CODE_PAGE = "cp1252"
_KILL = 9
"""What `Popen.kill` stands for here: TerminateProcess on Windows, which a process cannot catch."""


def windows() -> None:
    """Shapes this interpreter like Windows' CPython (see the module's docstring)."""
    for name in WINDOWS_MISSING_MODULES:
        sys.modules[name] = None  # type: ignore[assignment]
    for name in WINDOWS_MISSING_OS:
        if hasattr(os, name):
            delattr(os, name)
    for name in dir(signal):
        if name.startswith("SIG") and not name.startswith("SIG_") and name not in WINDOWS_SIGNALS:
            delattr(signal, name)
    for name in WINDOWS_MISSING_SIGNAL_CALLS:
        if hasattr(signal, name):
            delattr(signal, name)
    _windows_popen()
    _ansi_text()


def _windows_popen() -> None:
    original_init = subprocess.Popen.__init__

    def __init__(
        self: subprocess.Popen[Any],
        args: Any,
        *positional: Any,
        preexec_fn: Callable[[], Any] | None = None,
        pass_fds: Any = (),
        start_new_session: bool = False,
        process_group: int | None = None,
        **options: Any,
    ) -> None:
        if preexec_fn is not None:
            raise ValueError("preexec_fn is not supported on Windows platforms")
        if pass_fds:
            raise AssertionError("pass_fds not supported on Windows.")
        original_init(self, args, *positional, **options)

    def kill(self: subprocess.Popen[Any]) -> None:
        self.send_signal(_KILL)

    subprocess.Popen.__init__ = __init__  # type: ignore[method-assign]
    subprocess.Popen.kill = kill  # type: ignore[method-assign]


def _ansi_text() -> None:
    """Text opened without an encoding, and the standard streams, use the ANSI code page."""
    original_open = builtins.open

    def open_ansi(
        file: Any, mode: str = "r", buffering: int = -1, encoding: str | None = None, *args: Any, **kw: Any
    ) -> Any:
        if encoding in (None, "locale") and "b" not in mode:
            encoding = ANSI_CODE_PAGE
        return original_open(file, mode, buffering, encoding, *args, **kw)

    builtins.open = open_ansi
    io.open = open_ansi
    for stream in (sys.stdout, sys.stderr):
        if stream is not None:
            stream.reconfigure(encoding=ANSI_CODE_PAGE)


def macos() -> None:
    """Shapes this interpreter like a student's Mac (see the module's docstring)."""
    sysconfig.get_config_vars()  # read this build's configuration, named by the real platform, first
    sys.platform = "darwin"
    for name in ("sched_getaffinity", "sched_setaffinity"):
        if hasattr(os, name):
            delattr(os, name)
    os.getuid = os.geteuid = lambda: 501  # type: ignore[assignment]
    os.getgid = os.getegid = lambda: 20  # type: ignore[assignment]


SHAPES: dict[str, Callable[[], None]] = {"windows": windows, "macos": macos}
