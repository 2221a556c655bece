"""Shared by the Gradescope tests: a fixed bundle secret and Gradescope's submission metadata."""

from __future__ import annotations

SECRET = "5e" * 32
"""A fixed bundle secret, so that the tests' seeds are reproducible."""


def metadata(submission_id: int, created_at: str, *user_ids: int) -> dict[str, object]:
    """Gradescope's submission_metadata.json as its documentation shows it (fields gymgrade ignores too)."""
    return {
        "id": submission_id,
        "created_at": created_at,
        "assignment": {"due_date": "2026-12-01T23:00:00.000000-08:00", "id": 25828, "course_id": 1234,
                       "title": "OpenGym AI", "total_points": "6.0", "group_submission": True},
        "submission_method": "upload",
        "users": [{"email": f"s{user}@example.edu", "id": user, "name": f"S {user}"} for user in user_ids],
        "previous_submissions": [
            {"submission_time": "2026-11-20T10:00:00.000000-08:00", "score": 1.0,
             "results": {"score": 1.0, "tests": [], "extra_data": {"gymgrade": {"seed": 12345}}}},
        ],
    }  # fmt: skip
