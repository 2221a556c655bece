"""One assignment's LTI links, roster import and scores under /courses/{c}/assignments/{a}/lti: its course's
staff and the operator see that assignment's only; staff of another course find nothing, a student is
refused."""

from __future__ import annotations

import pytest
from api_testing import SettingsFactory, bearer, instructor_headers
from fastapi.testclient import TestClient

from api.lti.publisher import sync_outbox
from api.main import create_app
from api.models import Assignment, Course, LtiLink, LtiMember, LtiPlatform, LtiUser, Student, Submission

pytestmark = pytest.mark.slow  # each starts the service on a fresh database (about a second)


def _linked_course(client: TestClient, platform_id: int, slug: str) -> dict[str, object]:
    """Course ``slug`` with assignments lab1 and lab2, each opened by a link of its own, a learner of both
    links (an LTI enrolment) graded 0.5 in lab1 and 0.25 in lab2, and the course's TA: the TA's token and the
    links' ids."""
    operator = instructor_headers()
    client.post("/courses", json={"slug": slug, "title": slug}, headers=operator)
    ta = client.post(f"/courses/{slug}/staff", json={"name": "TA", "role": "ta"}, headers=operator).json()
    for lab in ("lab1", "lab2"):
        client.post(f"/courses/{slug}/assignments", json={"slug": lab, "title": lab}, headers=operator)
    sessions = client.app.state.context.sessions  # type: ignore[attr-defined]
    with sessions() as session:
        course = session.query(Course).filter_by(slug=slug).one()
        user = LtiUser(platform_id=platform_id, sub=f"learner-{slug}", name="Lee")
        session.add(user)
        session.flush()
        student = Student(course_id=course.id, name="Lee", token_sha256=f"{slug:0<64}", lti_user_id=user.id)
        session.add(student)
        links = {}
        for lab in ("lab1", "lab2"):
            assignment = session.query(Assignment).filter_by(course_id=course.id, slug=lab).one()
            link = LtiLink(
                platform_id=platform_id,
                deployment_id="d",
                context_id=f"context-{slug}",
                resource_link_id=f"{slug}-{lab}",
                assignment_id=assignment.id,
                title=lab,
                lineitem_url=f"https://lms.example/{slug}/{lab}",
                ags_scopes=[],
                custom={},
            )
            session.add(link)
            session.flush()
            session.add(LtiMember(link_id=link.id, user_id=user.id))
            links[lab] = link.id
        session.commit()
        student_id = student.id
    jobs = client.app.state.context.jobs  # type: ignore[attr-defined]
    for lab, score in (("lab1", 0.5), ("lab2", 0.25)):
        with sessions() as session:
            assignment = session.query(Assignment).filter_by(course_id=course.id, slug=lab).one()
            row = Submission(
                assignment_id=assignment.id,
                student_id=student_id,
                filename="opengym.py",
                sha256="0" * 64,
                content=b"x = 1\n",
                size=6,
                seed=1,
            )
            session.add(row)
            session.commit()
            submission_id = row.id
        assert jobs.claim("w", submission_id) is not None
        problems = [{"id": "car", "score": score, "max_score": 1.0}]
        assert jobs.complete(submission_id, "w", {"score": score, "max_score": 1.0, "problems": problems})
    with sessions() as session:
        sync_outbox(session)
    return {"ta": ta["token"], "links": links}


def test_staff_reach_their_own_assignments_lti_side_only(make_settings: SettingsFactory) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        with client.app.state.context.sessions() as session:  # type: ignore[attr-defined]
            platform = LtiPlatform(
                issuer="https://lms.example",
                client_id="c",
                deployment_ids=["d"],
                jwks_url="https://lms.example/jwks",
                auth_url="https://lms.example/auth",
                token_url="https://lms.example/token",
            )
            session.add(platform)
            session.commit()
            platform_id = platform.id
        a, b = _linked_course(client, platform_id, "a"), _linked_course(client, platform_id, "b")
        mine, theirs = bearer(str(a["ta"])), bearer(str(b["ta"]))
        a_links, b_links = a["links"], b["links"]
        assert isinstance(a_links, dict) and isinstance(b_links, dict)
        lab1, lab2 = "/courses/a/assignments/lab1/lti", "/courses/a/assignments/lab2/lti"

        links = client.get(f"{lab1}/links", headers=mine).json()
        assert [(link["id"], link["resource_link_id"]) for link in links] == [(a_links["lab1"], "a-lab1")]
        assert [link["id"] for link in client.get(f"{lab2}/links", headers=mine).json()] == [a_links["lab2"]]
        scores = client.get(f"{lab1}/scores", headers=mine).json()
        assert [(row["student"], row["link_id"], row["score"], row["status"]) for row in scores] == [
            ("Lee", a_links["lab1"], 0.5, "pending")
        ]
        lab2_scores = client.get(f"{lab2}/scores", headers=mine).json()
        assert [(row["link_id"], row["score"]) for row in lab2_scores] == [(a_links["lab2"], 0.25)]

        # the roster goes through a link of this assignment only (this one has no roster service: 400)
        no_service = client.post(f"{lab1}/links/{a_links['lab1']}/roster", headers=mine)
        assert no_service.status_code == 400 and "roster service" in no_service.json()["detail"]
        for other in (a_links["lab2"], b_links["lab1"], 0, 2**40):
            refused = client.post(f"{lab1}/links/{other}/roster", headers=mine)
            assert refused.status_code == 404, (other, refused.text)

        # staff of course b find nothing of a's; a student is refused; the operator sees a's
        student = client.post("/courses/a/students", json={"name": "Sam"}, headers=instructor_headers())
        for path in (f"{lab1}/links", f"{lab1}/scores"):
            assert client.get(path, headers=theirs).status_code == 404
            assert client.get(path, headers=bearer(student.json()["token"])).status_code == 403
        assert client.post(f"{lab1}/links/{a_links['lab1']}/roster", headers=theirs).status_code == 404
        assert client.get(f"{lab1}/scores", headers=instructor_headers()).json() == scores
        b_scores = client.get("/courses/b/assignments/lab1/lti/scores", headers=theirs).json()
        assert [row["link_id"] for row in b_scores] == [b_links["lab1"]]
