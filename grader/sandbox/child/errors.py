"""Errors raised by the child harness and by the protocol it shares with the parent."""


class HarnessError(Exception):
    """Root of every error raised by `grader.sandbox.child`."""


class ProtocolError(HarnessError):
    """Raised when a frame on the request or result channel is malformed, truncated or unexpected."""


class FrameTooLargeError(ProtocolError):
    """Raised when a frame is longer than the agreed maximum frame size."""

    def __init__(self, size: int, limit: int) -> None:
        super().__init__(f"a frame of {size} bytes exceeds the limit of {limit} bytes")
        self.size = size
        self.limit = limit


class InvalidValueError(HarnessError):
    """Raised when a value is not plain data (exact built-in types and numeric numpy arrays only).

    `where` names the offending position (e.g. ``[2]['q']``) and `message` explains the
    expected type, the type found and what to do.
    """

    def __init__(self, message: str, where: str = "") -> None:
        super().__init__(message)
        self.message = message
        self.where = where


class InvalidEpisodeLogError(ProtocolError):
    """Raised when an episode log decoded from the result channel does not have the agreed layout."""
