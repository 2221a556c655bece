"""Domain errors of the service; `api.handlers` maps each to its HTTP response in one place."""

from __future__ import annotations


class ServiceError(Exception):
    """Root of every error the service reports to a client; the message is shown to them as is."""


class MalformedBody(ServiceError):
    """Raised when a request body cannot be parsed at all (broken JSON or multipart framing)."""


class InvalidRequest(ServiceError):
    """Raised when a request parses but its parameters or body break the schema (a field missing or mistyped).

    Args:
        message: What was expected and what was found, for a person.
        problems: One ``(location, message, type)`` triple per offending field, for a program.
    """

    def __init__(self, message: str, problems: list[tuple[list[str | int], str, str]]) -> None:
        super().__init__(message)
        self.problems = problems


class PathNotFound(ServiceError):
    """Raised when a URL names no resource of the service."""


class MethodNotAllowed(ServiceError):
    """Raised when a resource exists but does not support the request's method.

    Args:
        message: What was expected and what was found.
        allowed: The methods the resource supports (sent in the ``Allow`` header).
    """

    def __init__(self, message: str, allowed: list[str]) -> None:
        super().__init__(message)
        self.allowed = allowed


class InternalError(ServiceError):
    """Raised (by the error handler, for the client) when the service itself failed on a request."""


class NotAuthenticated(ServiceError):
    """Raised when a request carries no token or a token that belongs to nobody."""


class InstructorOnly(ServiceError):
    """Raised when a student's (or a teaching assistant's) token is used on an instructor's endpoint."""


class OperatorOnly(ServiceError):
    """Raised when a course's token is used on the operator's endpoint (courses, LTI platforms and keys)."""


class CourseNotFound(ServiceError):
    """Raised when a course or assignment does not exist, or is not the caller's."""


class CourseExists(ServiceError):
    """Raised when a course or assignment is created under a slug that is already taken."""


class StaffNotFound(ServiceError):
    """Raised when a staff member's id is not one of the course's."""


class LinkNotFound(ServiceError):
    """Raised when an LTI resource link's id is not one of the links opening the assignment."""


class NoLatePolicy(ServiceError):
    """Raised when an extension is granted on an assignment without a late policy: it would change nothing."""


class StudentOnly(ServiceError):
    """Raised when the instructor's token is used to upload (submissions belong to students)."""


class SubmissionNotFound(ServiceError):
    """Raised when a submission does not exist or belongs to another student."""


class StudentNotFound(ServiceError):
    """Raised when a named student, or an enrolment's id, is not of the course."""


class GradingInProgress(ServiceError):
    """Raised when a regrade is asked of a submission that is queued or being graded already."""


class NothingGradedYet(ServiceError):
    """Raised when an override names a student none of whose uploads is graded yet: what each problem is worth
    comes from a graded report, so the override waits for one."""


class StudentExists(ServiceError):
    """Raised when a student is created under a name that is already taken."""


class InvalidStudentName(ServiceError):
    """Raised when a student name is empty, too long or holds control characters."""


class InvalidUpload(ServiceError):
    """Raised when an uploaded file cannot be a submission (wrong name, empty, binary, not UTF-8)."""


class UploadTooLarge(ServiceError):
    """Raised when an upload, or any request body, exceeds GYMGRADE_MAX_UPLOAD_BYTES (plus framing)."""


class LengthRequired(ServiceError):
    """Raised when an upload does not say its size up front (no Content-Length header)."""


class RateLimited(ServiceError):
    """Raised when a student uploads more often than GYMGRADE_RATE_LIMIT_PER_MINUTE allows."""

    def __init__(self, message: str, retry_after_seconds: int) -> None:
        super().__init__(message)
        self.retry_after_seconds = retry_after_seconds


class GraderUnavailable(ServiceError):
    """Raised when GYMGRADE_GRADER names nothing usable (reported at start-up or as the job's failure)."""


class GraderFailed(ServiceError):
    """Raised when the grader reports a failure of its own on a submission (stored as the job's failure)."""


class LtiRequestInvalid(ServiceError):
    """Raised when an LTI request (login initiation, registration) lacks what the LTI 1.3 spec requires."""


class LaunchRefused(ServiceError):
    """Raised when an LTI launch fails a check of the spec (issuer, audience, deployment, nonce, state,
    expiry, signature, message type or version); nothing of it is stored."""


class PlatformExists(ServiceError):
    """Raised when a platform is registered again under the same issuer and client id."""


class PlatformUnreachable(ServiceError):
    """Raised when a platform's endpoint (OpenID configuration, JWKS, token, registration) cannot be used."""


class OutboundRefused(PlatformUnreachable):
    """Raised when the tool refuses a request it would make for a platform: plain http, a loopback,
    link-local or private address, a host that is not the platform's, or an answer too large or too slow."""


class LtiKeysUnprotected(InternalError):
    """Raised when the LTI signing keys would be stored or read unencrypted outside development
    (GYMGRADE_KEY_ENCRYPTION_KEY unset), or cannot be decrypted with the key given."""
