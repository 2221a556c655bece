"""First code run in the child: applies rlimits (and Landlock in fallback mode), then starts the harness.

Run as ``python -S -B bootstrap.py CONFIG_JSON`` with a cleared environment; stdlib only, and nothing
POSIX-only imported unless a step asks for it (the parent decides what this system offers:
`grader.sandbox.host`). CONFIG_JSON holds ``sys_path``, ``no_new_privileges`` (Linux's prctl),
``rlimits`` ([name, soft, hard] triples), ``rlimits_may_fail`` (a limit the system refuses is named on
stderr instead of stopping the child), ``landlock`` ({"read": [...], "write":
[...]} or null), ``seccomp_fd`` (a BPF program to install, or null) and ``harness_argv`` (the
harness's own arguments).
"""

import ctypes
import importlib.util
import json
import os
import runpy
import sys

_PR_SET_NO_NEW_PRIVS = 38
_PR_SET_SECCOMP = 22
_SECCOMP_MODE_FILTER = 2


class _SockFprog(ctypes.Structure):
    _fields_ = [("len", ctypes.c_ushort), ("filter", ctypes.c_void_p)]


def _apply_landlock(rules: dict[str, list[str]]) -> None:
    location = os.path.join(os.path.dirname(os.path.abspath(__file__)), "landlock_syscalls.py")
    spec = importlib.util.spec_from_file_location("_gymgrade_landlock_syscalls", location)
    if spec is None or spec.loader is None:
        raise OSError(f"cannot load {location}")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.restrict_self(rules["read"], rules["write"])


def _apply_seccomp(descriptor: int) -> None:
    """Installs the parent's BPF program (bubblewrap does this itself when it is used)."""
    with os.fdopen(descriptor, "rb") as stream:
        program = stream.read()
    buffer = ctypes.create_string_buffer(program, len(program))
    fprog = _SockFprog(len(program) // 8, ctypes.cast(buffer, ctypes.c_void_p))
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(_PR_SET_SECCOMP, _SECCOMP_MODE_FILTER, ctypes.byref(fprog), 0, 0) != 0:
        raise OSError(ctypes.get_errno(), "prctl(PR_SET_SECCOMP) failed")


def main() -> None:
    config = json.loads(sys.argv[1])
    libc = ctypes.CDLL(None, use_errno=True) if config["no_new_privileges"] else None
    if libc is not None and libc.prctl(_PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0:
        raise OSError(ctypes.get_errno(), "prctl(PR_SET_NO_NEW_PRIVS) failed")
    for name, soft, hard in config["rlimits"]:
        import resource

        try:
            resource.setrlimit(getattr(resource, name), (soft, hard))
        except (ValueError, OSError):
            if not config["rlimits_may_fail"]:
                raise
            os.write(2, f"gymgrade: {name} cannot be set on this system\n".encode())
    if config["landlock"] is not None:
        _apply_landlock(config["landlock"])
    if config["seccomp_fd"] is not None:
        _apply_seccomp(config["seccomp_fd"])
    sys.path[:] = config["sys_path"]
    sys.argv = ["grader.sandbox.child", *config["harness_argv"]]
    runpy.run_module("grader.sandbox.child", run_name="__main__", alter_sys=True)


main()
