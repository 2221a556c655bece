"""A seccomp filter compiled in the parent: no sockets but AF_UNIX, no tracing, mounting or namespaces."""

from __future__ import annotations

import errno
import functools
import importlib
import os
import sys
from types import ModuleType
from typing import TYPE_CHECKING

from grader.sandbox.host import Feature
from grader.sandbox.isolation.layer import IsolationReport, LayerReport

if TYPE_CHECKING:
    from grader.sandbox.isolation.layer import LaunchSpec

DEBIAN_BINDINGS = "/usr/lib/python3/dist-packages"
_REMEDY = (
    "install the seccomp bindings: "
    "`apt-get install python3-seccomp` (Debian/Ubuntu) or `pip install pyseccomp`"
)

AF_UNIX = 1
CLONE_NEWUSER = 0x10000000
DENIED_SYSCALLS = (
    "ptrace",
    "process_vm_readv",
    "process_vm_writev",
    "kcmp",
    "mount",
    "umount2",
    "pivot_root",
    "chroot",
    "move_mount",
    "open_tree",
    "fsopen",
    "fsmount",
    "fsconfig",
    "fspick",
    "mount_setattr",
    "unshare",
    "setns",
    "kexec_load",
    "kexec_file_load",
    "reboot",
    "init_module",
    "finit_module",
    "delete_module",
    "bpf",
    "perf_event_open",
    "userfaultfd",
    "keyctl",
    "add_key",
    "request_key",
    "personality",
    "acct",
    "swapon",
    "swapoff",
    "syslog",
    "quotactl",
    "lookup_dcookie",
    "settimeofday",
    "clock_settime",
    "clock_adjtime",
    "adjtimex",
    "iopl",
    "ioperm",
    "open_by_handle_at",
    "name_to_handle_at",
    "io_uring_setup",
)
"""Denied with EPERM: nothing a grading child needs, and each is a known escape or kernel attack surface."""


def _bindings() -> ModuleType | None:
    for name in ("seccomp", "pyseccomp"):
        try:
            return importlib.import_module(name)
        except (ImportError, OSError):  # OSError: pyseccomp without the libseccomp shared library
            continue
    if DEBIAN_BINDINGS not in sys.path and os.path.isdir(DEBIAN_BINDINGS):
        sys.path.append(DEBIAN_BINDINGS)
        try:
            return importlib.import_module("seccomp")
        except (ImportError, OSError):
            return None
        finally:
            sys.path.remove(DEBIAN_BINDINGS)
    return None


def compile_filter() -> int:
    """Compiles the filter to BPF in a memfd and returns its descriptor (the caller closes it).

    Raises:
        OSError: when no seccomp bindings are installed or the filter cannot be built.
    """
    bindings = _bindings()
    if bindings is None:
        raise OSError(errno.ENOSYS, "no seccomp bindings: " + _REMEDY)
    deny = bindings.ERRNO(errno.EPERM)
    syscall_filter = bindings.SyscallFilter(defaction=bindings.ALLOW)
    for name in DENIED_SYSCALLS:
        try:
            syscall_filter.add_rule(deny, name)
        except (RuntimeError, ValueError, OSError):
            continue  # not a syscall on this kernel/architecture: nothing to deny
    syscall_filter.add_rule(
        bindings.ERRNO(errno.EAFNOSUPPORT), "socket", bindings.Arg(0, bindings.NE, AF_UNIX)
    )
    syscall_filter.add_rule(deny, "clone", bindings.Arg(0, bindings.MASKED_EQ, CLONE_NEWUSER, CLONE_NEWUSER))
    # clone3 passes its flags in memory a filter cannot read; glibc falls back to clone on ENOSYS.
    syscall_filter.add_rule(bindings.ERRNO(errno.ENOSYS), "clone3")
    descriptor = os.memfd_create("gymgrade-seccomp", 0)
    with os.fdopen(os.dup(descriptor), "wb") as stream:
        syscall_filter.export_bpf(stream)
    os.lseek(descriptor, 0, os.SEEK_SET)
    return descriptor


@functools.cache
def _probe_machine() -> LayerReport:
    """Compiles the filter once to see that the bindings work."""
    try:
        os.close(compile_filter())
    except OSError as error:
        return LayerReport(
            SeccompLayer.name, False, f"cannot build the syscall filter ({error.strerror})", _REMEDY
        )
    return LayerReport(
        SeccompLayer.name,
        True,
        f"{len(DENIED_SYSCALLS)} syscalls denied (ptrace, mount, namespaces, bpf, keyctl, ...), sockets limited to AF_UNIX",  # noqa: E501
    )


class SeccompLayer:
    """A syscall filter installed before any student code runs: by bubblewrap (`--seccomp FD`) before
    the child starts, else by the child's bootstrap."""

    name = "seccomp"
    needs: tuple[Feature, ...] = (Feature.LINUX_KERNEL,)
    guards = "the denied system calls"

    def probe(self, outer: IsolationReport) -> LayerReport:
        """Whether the filter can be built here (checked once per process)."""
        return _probe_machine()

    def apply(self, spec: LaunchSpec) -> None:
        """Compiles the filter into a descriptor the child inherits and asks the bootstrap to install it."""
        descriptor = compile_filter()
        spec.launch.pass_fds.append(descriptor)
        spec.bootstrap.seccomp_fd = descriptor
