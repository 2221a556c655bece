"""Resource limits (the sandbox's `Limits`, one call's `CallBudget`) and the policy deciding whether weaker
isolation is acceptable."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

MIB = 1 << 20
GIB = 1 << 30


class IsolationPolicy(StrEnum):
    """What to do when a layer of isolation cannot be enforced on this machine."""

    REQUIRE_FULL = "require_full"
    """Instructor grading and the service: refuse to run (`IsolationUnavailable`) unless every layer works."""

    ALLOW_FALLBACK = "allow_fallback"
    """A student's own `gymgrade check`: run with the strongest layers available and say which are missing."""


@dataclass(frozen=True)
class Limits:
    """Per-call and per-child limits.

    Attributes:
        call_seconds: Wall-clock seconds one call may take (the parent kills the child afterwards).
        import_seconds: Wall-clock seconds importing the submission may take.
        cpu_seconds: CPU seconds one child process may use over its life (RLIMIT_CPU, a backstop).
        memory_bytes: Memory of the child's whole process tree (cgroup), also the address-space rlimit.
        max_pids: Processes and threads the child's tree may hold at once.
        output_bytes: Student stdout and stderr kept per call (each); the rest is counted and dropped.
        scratch_bytes: Size of the writable tmpfs the child sees as HOME and TMPDIR.
        file_bytes: Largest file the child may write (RLIMIT_FSIZE).
        open_files: File descriptors the child may hold (RLIMIT_NOFILE).
        frame_bytes: Largest result frame (return value plus episode logs) the parent accepts.
    """

    call_seconds: float = 60.0
    import_seconds: float = 30.0
    cpu_seconds: int = 3600
    memory_bytes: int = 2 * GIB
    max_pids: int = 64
    output_bytes: int = 64 * 1024
    scratch_bytes: int = 64 * MIB
    file_bytes: int = 32 * MIB
    open_files: int = 256
    frame_bytes: int = 64 * MIB

    def __post_init__(self) -> None:
        if self.memory_bytes < 1536 * MIB:
            raise ValueError(
                f"memory_bytes must be at least 1.5 GiB (numpy and gymnasium need that much address space); "
                f"found {self.memory_bytes} bytes: raise the limit"
            )
        for name in (
            "call_seconds",
            "import_seconds",
            "cpu_seconds",
            "max_pids",
            "output_bytes",
            "scratch_bytes",
            "file_bytes",
            "open_files",
            "frame_bytes",
        ):
            if getattr(self, name) <= 0:
                raise ValueError(f"{name} must be positive; found {getattr(self, name)}")


@dataclass(frozen=True)
class CallBudget:
    """What one call may record: resets (played or not) and steps summed over its episodes.

    The child stops recording once either is exceeded and the call ends with
    `OutcomeStatus.EPISODE_LIMIT`; the parent also derives from it the largest result frame it parses
    (`grader.sandbox.child.budget.frame_limits`).

    Attributes:
        max_episodes: Resets the call may make (every `reset`, whether or not a step follows).
        max_steps: Steps the call may take, summed over all its episodes.
    """

    max_episodes: int
    max_steps: int

    def __post_init__(self) -> None:
        for name in ("max_episodes", "max_steps"):
            value = getattr(self, name)
            if type(value) is not int or value < 0:
                raise ValueError(f"CallBudget.{name} must be a non-negative int; found {value!r}")
