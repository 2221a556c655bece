"""Regrading in the service: one upload or one student's uploads queued again on their recorded seeds,
nobody else's touched, the instructor's overrides kept; a student's token and a job in progress refused."""

from __future__ import annotations

from api_testing import SettingsFactory, add_student, bearer, graded_upload, instructor_headers
from fastapi.testclient import TestClient

from api.main import create_app


def _status(client: TestClient, submission_id: int) -> tuple[str, int | None, object]:
    view = client.get(f"/submissions/{submission_id}", headers=instructor_headers()).json()
    return view["status"], view["seed"], view["report"]


def test_one_upload_is_regraded_on_its_seed_and_keeps_its_override(make_settings: SettingsFactory) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        ada, bob = add_student(client, "ada"), add_student(client, "bob")
        first = graded_upload(client, ada, {"random_blackjack": 0.0})
        other = graded_upload(client, bob, {"random_blackjack": 1.0})
        seed = _status(client, first)[1]
        override = {
            "problem": "random_blackjack",
            "points": 1,
            "reason": "checked by hand",
            "submission_id": first,
        }
        assert (
            client.post("/students/ada/overrides", json=override, headers=instructor_headers()).status_code
            == 201
        )
        response = client.post(f"/submissions/{first}/regrade", headers=instructor_headers())
        assert (response.status_code, response.json(), response.headers["location"]) == (
            202, {"id": first, "status": "queued"}, f"/submissions/{first}",
        )  # fmt: skip
        assert _status(client, first) == ("queued", seed, None)
        assert _status(client, other)[0] == "done", "nobody else's upload is touched"
        again = client.post(f"/submissions/{first}/regrade", headers=instructor_headers())
        assert again.status_code == 409 and "is queued already" in again.json()["detail"]
        jobs = client.app.state.context.jobs  # type: ignore[attr-defined]
        job = jobs.claim("test-worker")
        assert (job.submission_id, job.seed) == (first, seed)
        report = {
            "score": 0.0,
            "max_score": 1.0,
            "problems": [{"id": "random_blackjack", "score": 0.0, "max_score": 1.0}],
        }
        assert jobs.complete(first, "test-worker", report)
        gradebook = client.get("/gradebook.csv", headers=instructor_headers()).text
        assert "ada," in gradebook and "checked by hand" in gradebook.splitlines()[1]


def test_a_students_uploads_are_regraded_together_and_a_student_cannot(
    make_settings: SettingsFactory,
) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        ada, bob = add_student(client, "ada"), add_student(client, "bob")
        uploads = [graded_upload(client, ada, {"car": 0.0}) for _ in range(2)]
        theirs = graded_upload(client, bob, {"car": 1.0})
        assert client.post(f"/submissions/{uploads[0]}/regrade", headers=bearer(ada)).status_code == 403
        assert client.post("/students/ada/regrade", headers=bearer(ada)).status_code == 403
        response = client.post("/students/ada/regrade", headers=instructor_headers())
        assert response.status_code == 202
        assert sorted(item["id"] for item in response.json()) == uploads
        assert [_status(client, upload)[0] for upload in [*uploads, theirs]] == ["queued", "queued", "done"]
        assert client.post("/students/nobody/regrade", headers=instructor_headers()).status_code == 404
