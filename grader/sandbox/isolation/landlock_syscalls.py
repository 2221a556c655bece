"""Landlock's system calls (Linux >= 5.13) through ctypes, for the layer in `landlock.py`.

Self-contained (stdlib only): the parent probes the ABI with it, and the child's bootstrap loads it from
the harness tree to restrict itself.
"""

from __future__ import annotations

import ctypes
import os
import platform

_SYSCALLS = {"create_ruleset": 444, "add_rule": 445, "restrict_self": 446}
_CREATE_RULESET_VERSION = 1
_RULE_PATH_BENEATH = 1
_PR_SET_NO_NEW_PRIVS = 38

EXECUTE, WRITE_FILE, READ_FILE, READ_DIR = 1 << 0, 1 << 1, 1 << 2, 1 << 3
_WRITE_EXTRA = sum(1 << bit for bit in range(4, 13))  # remove/make dir, file, fifo, socket, symlink, devices
_REFER, _TRUNCATE = 1 << 13, 1 << 14
_NET_BIND_TCP, _NET_CONNECT_TCP = 1 << 0, 1 << 1
_SCOPE_ABSTRACT_UNIX_SOCKET, _SCOPE_SIGNAL = 1 << 0, 1 << 1
SCOPED_ABI = 6
"""From this ABI on, a restricted process can neither signal nor reach by abstract socket any process
outside its own domain: the grader and the other children (kill -1 as root, where no uid could be
dropped, reached them)."""


class _RulesetAttr(ctypes.Structure):
    _fields_ = [
        ("handled_access_fs", ctypes.c_uint64),
        ("handled_access_net", ctypes.c_uint64),
        ("scoped", ctypes.c_uint64),
    ]


class _PathBeneathAttr(ctypes.Structure):
    _pack_ = 1
    _fields_ = [("allowed_access", ctypes.c_uint64), ("parent_fd", ctypes.c_int32)]


def _libc() -> ctypes.CDLL:
    return ctypes.CDLL(None, use_errno=True)


def abi_version() -> int:
    """The Landlock ABI of the running kernel, 0 when Landlock is unavailable (or not Linux x86-64/arm64)."""
    if platform.system() != "Linux" or platform.machine() not in ("x86_64", "aarch64"):
        return 0
    result = _libc().syscall(
        _SYSCALLS["create_ruleset"], None, ctypes.c_size_t(0), ctypes.c_uint32(_CREATE_RULESET_VERSION)
    )
    return max(int(result), 0)


def _handled(abi: int) -> int:
    handled = EXECUTE | WRITE_FILE | READ_FILE | READ_DIR | _WRITE_EXTRA
    if abi >= 2:
        handled |= _REFER
    if abi >= 3:
        handled |= _TRUNCATE
    return handled


def restrict_self(read_paths: list[str], write_paths: list[str]) -> int:
    """Restricts this process and its future children to reading `read_paths` and writing `write_paths`.

    With ABI 4 or later, TCP bind and connect are denied as well; with ABI 6 or later, signals and
    abstract Unix sockets reach no process outside this one's domain (`SCOPED_ABI`). Paths that do not
    exist are skipped.

    Returns:
        The ABI version applied.

    Raises:
        OSError: when Landlock is unavailable or a call fails.
    """
    abi = abi_version()
    if abi < 1:
        raise OSError("Landlock is not available in this kernel")
    libc = _libc()
    handled = _handled(abi)
    scoped = _SCOPE_ABSTRACT_UNIX_SOCKET | _SCOPE_SIGNAL if abi >= SCOPED_ABI else 0
    attr = _RulesetAttr(handled, _NET_BIND_TCP | _NET_CONNECT_TCP if abi >= 4 else 0, scoped)
    fields = 3 if abi >= SCOPED_ABI else 2 if abi >= 4 else 1
    size = fields * ctypes.sizeof(ctypes.c_uint64)
    ruleset = libc.syscall(
        _SYSCALLS["create_ruleset"], ctypes.byref(attr), ctypes.c_size_t(size), ctypes.c_uint32(0)
    )
    if ruleset < 0:
        raise OSError(ctypes.get_errno(), "landlock_create_ruleset failed")
    try:
        read_access = EXECUTE | READ_FILE | READ_DIR
        for paths, access in ((read_paths, read_access), (write_paths, handled)):
            for path in paths:
                _add_rule(libc, ruleset, path, access)
        if libc.prctl(_PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0:
            raise OSError(ctypes.get_errno(), "prctl(PR_SET_NO_NEW_PRIVS) failed")
        if libc.syscall(_SYSCALLS["restrict_self"], ruleset, ctypes.c_uint32(0)) != 0:
            raise OSError(ctypes.get_errno(), "landlock_restrict_self failed")
    finally:
        os.close(ruleset)
    return abi


def _add_rule(libc: ctypes.CDLL, ruleset: int, path: str, access: int) -> None:
    try:
        descriptor = os.open(path, os.O_PATH | os.O_CLOEXEC)
    except FileNotFoundError:
        return
    try:
        if not os.path.isdir(path):
            access &= EXECUTE | WRITE_FILE | READ_FILE | _TRUNCATE
        rule = _PathBeneathAttr(access, descriptor)
        if (
            libc.syscall(
                _SYSCALLS["add_rule"], ruleset, _RULE_PATH_BENEATH, ctypes.byref(rule), ctypes.c_uint32(0)
            )
            != 0
        ):
            raise OSError(ctypes.get_errno(), f"landlock_add_rule failed for {path}")
    finally:
        os.close(descriptor)
