"""The machines gymgrade is deployed on, built around one command: a PID namespace sharing the host's
cgroups, a container as Docker runs one by default, Gradescope's autograder container.

Each shape is a command prefix; nothing here needs Docker. Used by `test_deployment_shapes.py` and
`bench/deployment_shapes.py`. Every shape starts its command in a new session, so that even a grader that
signalled its own process group could not reach the caller.

The Docker-default shape (`DOCKER_DEFAULT`) is this file run as a program inside `unshare --mount --pid
--fork --mount-proc`: it remounts every cgroup mount read-only (Docker mounts `/sys/fs/cgroup` so),
installs a system-call filter shaped like Docker's default profile (no `unshare`, `setns`, `mount`, no
`clone` with a namespace flag, `clone3` answered ENOSYS, no keyrings, bpf or perf: so no bubblewrap and
no new user namespace), then drops every capability Docker does not grant (`setpriv`: `CAP_SYS_ADMIN`
among them) and execs the command as root. Gradescope's autograder runs as root in such a container.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tomllib
import zipfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[3]
HONEST = ROOT / "submissions" / "classic_complete.py"
HOSTILE = ROOT / "submissions" / "hostile"
SHAPE_HOSTILE = ("kill_parent.py", "fork_bomb.py", "memory_bomb.py", "big_file.py")
"""The hostile samples every shape grades: they kill (kill -1), fork, fill memory and fill the disk."""
GYMGRADE = [sys.executable, "-m", "grader"]

THIS_FILE = Path(__file__).resolve()
PID_NAMESPACE = ("unshare", "--pid", "--fork", "--mount-proc", "--")
"""A PID namespace sharing the host's cgroups, mounts and file system (privileged containers, pods,
systemd-nspawn, CI runners): processes outside it read as 0 in `cgroup.procs`."""
DOCKER_DEFAULT = (
    "unshare", "--mount", "--pid", "--fork", "--mount-proc", "--",
    sys.executable, str(THIS_FILE), "docker", "--",
)  # fmt: skip
"""A container as Docker runs one by default (see the module's docstring)."""
DOCKER_CAPABILITIES = (
    "chown", "dac_override", "fsetid", "fowner", "mknod", "net_raw", "setgid", "setuid", "setfcap", "setpcap",
    "net_bind_service", "sys_chroot", "kill", "audit_write",
)  # fmt: skip
"""The capabilities Docker grants a container's root by default (moby's `DefaultCapabilities`)."""
NAMESPACE_FLAGS = (0x00020000, 0x04000000, 0x08000000, 0x10000000, 0x20000000, 0x40000000, 0x02000000)
"""CLONE_NEWNS, NEWUTS, NEWIPC, NEWUSER, NEWPID, NEWNET, NEWCGROUP: Docker refuses a clone with any."""
DOCKER_DENIED = (
    "unshare", "setns", "mount", "umount2", "pivot_root", "move_mount", "open_tree", "fsopen", "fsmount",
    "fsconfig", "fspick", "mount_setattr", "keyctl", "add_key", "request_key", "bpf", "perf_event_open",
    "userfaultfd", "kexec_load", "kexec_file_load", "reboot", "init_module", "finit_module", "delete_module",
    "open_by_handle_at", "name_to_handle_at", "acct", "swapon", "swapoff", "syslog", "quotactl",
    "lookup_dcookie", "settimeofday", "clock_settime", "clock_adjtime", "iopl", "ioperm",
)  # fmt: skip
"""System calls Docker's default profile refuses a container without CAP_SYS_ADMIN (EPERM)."""


def can_build_shapes() -> str | None:
    """Why the shapes cannot be built here (None when they can): they need root and util-linux."""
    if os.geteuid() != 0:
        return "deployment shapes need root (namespaces, mounts, capability bounding sets)"
    missing = [tool for tool in ("unshare", "setpriv", "mount") if shutil.which(tool) is None]
    if missing:
        return f"deployment shapes need util-linux's {', '.join(missing)}"
    return None


def run_in(
    shape: Sequence[str], argv: Sequence[str], *, cwd: Path = ROOT, timeout: float = 600
) -> subprocess.CompletedProcess[str]:
    """Runs `argv` inside `shape` in a new session; `timeout` only bounds a hang."""
    return subprocess.run(
        [*shape, *argv],
        cwd=cwd,
        capture_output=True,
        text=True,
        start_new_session=True,
        timeout=timeout,
        check=False,
    )


GRADESCOPE = DOCKER_DEFAULT
"""Gradescope's autograder: root in a Docker-default container, running the bundle's `run_autograder`."""


def hostile_upload(file: str) -> str:
    """The honest solution whose `random_blackjack` does what a hostile sample's function does."""
    sample = hostile_sample(file)
    hostile = (HOSTILE / file).read_text(encoding="utf-8")
    call = f"\n\ndef random_blackjack(n):\n    return {sample['function']}()\n"
    return HONEST.read_text(encoding="utf-8") + "\n\n" + hostile + call


def gradescope_root(directory: Path, upload: str) -> Path:
    """Gradescope's /autograder for one upload, from the bundle the docs build (`gymgrade
    gradescope-bundle`; random_blackjack alone): `source/`, `submission/opengym.py`, the metadata."""
    from grader.cli.gradescope import bundle
    from grader.lab.problems import PROBLEM_IDS
    from grader.submission.gradescope_upload import METADATA_FILE
    from tests.grader.gradescope_support import SECRET, metadata
    from tests.grader.grading_support import write_config

    overrides: dict[str, dict[str, Any]] = {problem: {"enabled": False} for problem in PROBLEM_IDS}
    overrides["random_blackjack"] = {"enabled": True}
    config = write_config(directory / "assignment.toml", overrides)
    archive = bundle(directory / "autograder.zip", config=config, secret=SECRET)
    root = directory / "autograder"
    with zipfile.ZipFile(archive) as opened:
        opened.extractall(root / "source")
    os.chmod(root / "source" / "run_autograder", 0o755)
    (root / "submission").mkdir()
    (root / "submission" / "opengym.py").write_text(upload, encoding="utf-8")
    (root / METADATA_FILE).write_text(json.dumps(metadata(4601, "2026-12-07T21:00:00.000000-08:00", 7)))
    return root


def run_autograder_argv(root: Path) -> list[str]:
    """The bundle's `run_autograder`, moved to `root` and run with this checkout's grader (as the bundle's
    own tests do; `setup.sh` would install the same sources into /opt/gymgrade)."""
    return [
        "env",
        f"GYMGRADE_AUTOGRADER_ROOT={root}",
        f"GYMGRADE_COMMAND={sys.executable} -m grader.cli",
        f"PYTHONPATH={ROOT}",
        str(root / "source" / "run_autograder"),
    ]


def _cgroup_mounts() -> list[str]:
    mounts = Path("/proc/self/mounts").read_text(encoding="utf-8").splitlines()
    targets = [line.split()[1] for line in mounts]
    return [
        target for target in targets if target == "/sys/fs/cgroup" or target.startswith("/sys/fs/cgroup/")
    ]


def _docker_filter() -> None:
    """Installs a filter shaped like Docker's default profile on this process (inherited by what it execs)."""
    from grader.sandbox.isolation.seccomp import _bindings

    bindings = _bindings()
    if bindings is None:
        raise SystemExit("the Docker-default shape needs the seccomp bindings (python3-seccomp)")
    deny = bindings.ERRNO(1)  # EPERM
    syscall_filter = bindings.SyscallFilter(defaction=bindings.ALLOW)
    syscall_filter.set_attr(bindings.Attr.CTL_NNP, 0)  # as Docker: no no-new-privileges unless asked
    for name in DOCKER_DENIED:
        try:
            syscall_filter.add_rule(deny, name)
        except (RuntimeError, ValueError, OSError):
            continue
    for flag in NAMESPACE_FLAGS:
        syscall_filter.add_rule(deny, "clone", bindings.Arg(0, bindings.MASKED_EQ, flag, flag))
    syscall_filter.add_rule(bindings.ERRNO(38), "clone3")  # ENOSYS: glibc falls back to clone
    syscall_filter.load()


def docker_default(argv: list[str]) -> None:
    """Becomes the Docker-default container (inside `unshare --mount --pid --fork`) and runs `argv` in it.

    This process stays the container's init (as `docker run --init`), so the command is not: the kernel
    spares a namespace's init the signals of its own namespace, and a grader running as init would
    survive a child's kill(-1) that would end it anywhere else.
    """
    for target in _cgroup_mounts():
        subprocess.run(["mount", "-o", "remount,bind,ro", target], check=True)
    _docker_filter()
    keep = ",".join(f"+{name}" for name in DOCKER_CAPABILITIES)
    command = subprocess.run(["setpriv", "--bounding-set", f"-all,{keep}", "--inh-caps", "-all", "--", *argv])
    code = command.returncode
    sys.exit(128 - code if code < 0 else code)


def hostile_sample(file: str) -> dict[str, Any]:
    """The sample of `file` in submissions/hostile/outcomes.toml (function, expected status, ...)."""
    samples = tomllib.loads((HOSTILE / "outcomes.toml").read_text(encoding="utf-8"))["sample"]
    sample: dict[str, Any] = next(sample for sample in samples if sample["file"] == file)
    return sample


def hostile_outcome(file: str) -> dict[str, Any]:
    """Calls a hostile sample's function, then `ok()`, in a sandbox with whatever layers this machine
    allows (as `check` and Gradescope grade), with test_hostile.py's limits."""
    from grader.sandbox import Call, IsolationPolicy, Limits, Sandbox

    sample = hostile_sample(file)
    limits = Limits(
        call_seconds=sample.get("call_seconds", 2),
        import_seconds=6,
        memory_bytes=1536 << 20,
        max_pids=32,
        output_bytes=4096,
        scratch_bytes=16 << 20,
        file_bytes=8 << 20,
    )
    with Sandbox(HOSTILE / file, seed=7, limits=limits, policy=IsolationPolicy.ALLOW_FALLBACK) as sandbox:
        outcome = sandbox.call(Call(sample["function"]))
        following = sandbox.call(Call("ok"))
        missing = [layer.name for layer in sandbox.isolation.missing]
    return {
        "status": outcome.status.value,
        "value": outcome.value,
        "message": outcome.message,
        "following": [following.status.value, following.value],
        "missing": missing,
        "leftovers": sandbox.leftovers,
    }


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    if sys.argv[1] == "docker":
        docker_default(sys.argv[sys.argv.index("--") + 1 :])
    elif sys.argv[1] == "hostile":
        print(json.dumps(hostile_outcome(sys.argv[2])))
