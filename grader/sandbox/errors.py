"""Errors raised by the parent side of the sandbox (failures of student code are outcomes, not errors)."""


class SandboxError(Exception):
    """Root of every error raised by `grader.sandbox` on the parent side."""


class IsolationUnavailable(SandboxError):
    """Raised when `IsolationPolicy.REQUIRE_FULL` is asked for and a layer of isolation cannot be enforced.

    The message names each missing layer and how to make it available.
    """


class SandboxClosedError(SandboxError):
    """Raised when a call is made on a `Sandbox` that has already been closed."""


class SandboxLayoutError(SandboxError):
    """Raised when the interpreter's directories cannot be shown to the child as they are on the host.

    The message names the directory, why it cannot be bound, and what to install instead.
    """
