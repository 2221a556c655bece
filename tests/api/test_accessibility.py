"""Every page passes axe-core's WCAG 2.0/2.1/2.2 A and AA rules in Chromium: the service's pages (signed out,
as a student, the operator, a course's instructor and its teaching assistant, the error page, the forms'
answers, the LTI registration form), and the pages gymgrade writes: the ``check --html`` report, the class
report (its links 24 pixels, WCAG 2.2's target size) and the similarity page."""

from __future__ import annotations

import shutil
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import httpx
import pytest
from accessibility import CHROMIUM, CHROMIUM_ARGS, assert_accessible, axe_violations
from api_testing import INSTRUCTOR_TOKEN, instructor_headers
from cryptography.fernet import Fernet
from live_server import (
    E2E_GRADER,
    PARTIAL_SOLUTION,
    LiveProcess,
    create_student,
    service_environment,
    upload,
    wait_for,
)

from api.deps import SESSION_COOKIE
from api.lti.deep_linking import choices, graded_edition
from api.web import templates
from grader.classroom.report import ClassEntry, write_class_report
from grader.cli import main
from grader.lab.assignment import load_config
from grader.render.html import render_html
from grader.report import Report

pytestmark = [pytest.mark.browser, pytest.mark.e2e, pytest.mark.sandbox]

SIMILARITY_CORPUS = Path(__file__).resolve().parents[2] / "submissions" / "similarity"


@dataclass(frozen=True)
class Service:
    """A real service with one graded upload, a second course with an instructor, a TA, a student and an
    assignment with one graded upload, and a ticket."""

    process: LiveProcess
    tokens: dict[str, str]
    """Each role's token: student, operator, and of course rl-b: instructor, ta, student-b."""
    submission: int
    submission_b: int
    """The upload of rl-b's student to rl-b's assignment pfi."""
    report: dict[str, Any]
    registration_url: str


@pytest.fixture(scope="module")
def chromium() -> Iterator[Any]:
    if shutil.which(CHROMIUM) is None:
        pytest.skip(f"Chromium is not installed at {CHROMIUM} (apt-get install -y chromium)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="pip install playwright")
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
        yield browser
        browser.close()


@pytest.fixture(scope="module")
def service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Service]:
    folder = tmp_path_factory.mktemp("accessible")
    key = Fernet.generate_key().decode("ascii")  # the LTI signing keys are kept encrypted
    env = service_environment(folder / "data", E2E_GRADER, workers=1, key_encryption_key=key)
    process = LiveProcess("serve", env, folder / "log")
    process.start()
    try:
        student = create_student(process.url, "ada")
        submission = upload(process.url, student, PARTIAL_SOLUTION)
        graded = wait_for(process.url, INSTRUCTOR_TOKEN, submission, {"done", "failed"})
        assert graded["status"] == "done", graded
        staff = {}
        _post(process.url, "/courses", {"slug": "rl-b", "title": "Reinforcement Learning B"})
        for name, role in (("Grace", "instructor"), ("Alan", "ta")):
            staff[role] = _post(process.url, "/courses/rl-b/staff", {"name": name, "role": role})["token"]
        _post(process.url, "/courses/rl-b/assignments", {"slug": "pfi", "title": "PFI", "edition": "v2026"})
        staff["student-b"] = _post(process.url, "/courses/rl-b/students", {"name": "bea"})["token"]
        pfi = process.url + "/courses/rl-b/assignments/pfi"
        submission_b = upload(pfi, staff["student-b"], PARTIAL_SOLUTION)
        graded_b = wait_for(pfi, staff["student-b"], submission_b, {"done", "failed"})
        assert graded_b["status"] == "done", graded_b
        yield Service(
            process=process,
            tokens={"student": student, "operator": INSTRUCTOR_TOKEN, "instructor": staff["instructor"],
                    "ta": staff["ta"], "student-b": staff["student-b"]},
            submission=submission,
            submission_b=submission_b,
            report=graded["report"],
            registration_url=_post(process.url, "/lti/registrations", {})["url"],
        )  # fmt: skip
    finally:
        process.stop()


def _post(base_url: str, path: str, body: dict[str, Any]) -> dict[str, Any]:
    response = httpx.post(base_url + path, json=body, headers=instructor_headers())
    response.raise_for_status()
    answer: dict[str, Any] = response.json()
    return answer


def _fill_and_send(form: str, **fields: str) -> Callable[[Any], None]:
    def act(page: Any) -> None:
        for name, value in fields.items():
            page.fill(f"{form} [name={name}]", value)
        with page.expect_navigation():
            page.click(f"{form} button[type=submit]")

    return act


@dataclass(frozen=True)
class Visit:
    """A page as a role reaches it: its path, then what the visitor does there before axe-core looks."""

    shows: str
    """A selector of what the page must show once there (the state axe-core looked at)."""
    role: str | None
    path: str
    act: Callable[[Any], None] | None = None


VISITS = {
    "sign-in": Visit("#sign-in", None, "/"),
    "sign-in-refused": Visit("p.error", None, "/", _fill_and_send("#sign-in", token="gg_not-a-token")),
    "error-signed-out": Visit("p.error", None, "/ui/submissions/{submission}"),
    "error-not-found": Visit("p.error", "student", "/ui/submissions/999999"),
    "student-home": Visit("#upload", "student", "/"),
    "student-report": Visit("#score", "student", "/ui/submissions/{submission}"),
    "operator-home": Visit("#override", "operator", "/"),
    "operator-report": Visit("#score", "operator", "/ui/submissions/{submission}"),
    "override-kept": Visit(
        "#override-result.notice",
        "operator",
        "/",
        _fill_and_send("#override", student="ada", problem="blackjack", points="1", reason="ok"),
    ),
    "override-refused": Visit(
        "#override-result.error",
        "operator",
        "/",
        _fill_and_send("#override", student="nobody", problem="blackjack", points="1", reason="x"),
    ),
    "operator-courses": Visit("#new-course", "operator", "/ui/courses"),
    "course-refused": Visit(
        "#course-error",
        "operator",
        "/ui/courses",
        _fill_and_send("#new-course", slug="Not A Slug", title="x"),
    ),
    "operator-course": Visit("#new-staff", "operator", "/ui/courses/default"),
    "staff-token-shown": Visit(
        "#staff-token", "operator", "/ui/courses/rl-b", _fill_and_send("#new-staff", name="Ada Lovelace")
    ),
    "instructor-courses": Visit("#courses", "instructor", "/ui/courses"),
    "instructor-course": Visit("#new-assignment", "instructor", "/ui/courses/rl-b"),
    "assignment-refused": Visit(
        "#assignment-error",
        "instructor",
        "/ui/courses/rl-b",
        _fill_and_send("#new-assignment", slug="pfi", title="again"),
    ),
    "assignment-added": Visit(
        "#course-notice",
        "instructor",
        "/ui/courses/rl-b",
        _fill_and_send("#new-assignment", slug="lab-1", title="Lab 1"),
    ),
    "ta-course": Visit("#assignments", "ta", "/ui/courses/rl-b"),
    "student-course": Visit("#assignments", "student-b", "/ui/courses/rl-b"),
    "assignment-student-home": Visit("#upload", "student-b", "/ui/courses/rl-b/assignments/pfi"),
    "assignment-student-report": Visit(
        "#live", "student-b", "/ui/courses/rl-b/assignments/pfi/submissions/{submission_b}"
    ),
    "assignment-ta-home": Visit("#gradebook", "ta", "/ui/courses/rl-b/assignments/pfi"),
    "assignment-ta-report": Visit(
        "#live", "ta", "/ui/courses/rl-b/assignments/pfi/submissions/{submission_b}"
    ),
    "assignment-override-kept": Visit(
        "#override-result.notice",
        "instructor",
        "/ui/courses/rl-b/assignments/pfi",
        _fill_and_send("#override", student="bea", problem="total", points="1", reason="ok"),
    ),
    "error-other-course-report": Visit("p.error", "student-b", "/ui/submissions/{submission}"),
    "error-other-course": Visit("p.error", "ta", "/ui/courses/default"),
    "lti-registration-form": Visit(
        "#lti-register", None, "{registration_url}&openid_configuration=https://lms.example/.well-known"
    ),
    "lti-error": Visit("p.error", None, "/lti/login"),
}


@pytest.mark.parametrize("name", list(VISITS))
def test_every_service_page_passes_wcag_a_and_aa(chromium: Any, service: Service, name: str) -> None:
    visit = VISITS[name]
    context = chromium.new_context()
    try:
        if visit.role is not None:
            token = service.tokens[visit.role]
            context.add_cookies([{"name": SESSION_COOKIE, "value": token, "url": service.process.url}])
        page = context.new_page()
        path = visit.path.format(
            submission=service.submission,
            submission_b=service.submission_b,
            registration_url=service.registration_url,
        )
        page.goto(path if path.startswith("http") else service.process.url + path)
        if visit.act is not None:
            visit.act(page)
        assert page.locator("main h1").count() == 1, page.content()
        assert page.locator(visit.shows).count() >= 1, f"{name}: expected {visit.shows} on\n{page.content()}"
        assert_accessible(page, name)
    finally:
        context.close()


LTI_PAGES = {
    "lti-storage": ("lti_storage.html", {"action": "get", "target": "_parent", "origin": "https://lms.example",
                    "key": "k", "value": "", "next": "", "id_token": "t", "state": "s"}),
    "lti-picker": ("lti_picker.html", {"choices": choices(), "graded": graded_edition("rl1"), "picker": "p"}),
    "lti-picker-assignments": ("lti_picker.html", {"choices": choices(), "graded": graded_edition("rl1"),
                               "picker": "p", "assignments": [
                                   (SimpleNamespace(slug="lab-1", title="Lab 1"), "rl1"),
                                   (SimpleNamespace(slug="lab-2", title="Lab 2"), "v2026")]}),
    "lti-post": ("lti_post.html", {"action": "https://lms.example/deep-link", "jwt": "j"}),
    "lti-registered": ("lti_registered.html", {"platform": {"issuer": "https://lms.example", "client_id": "c",
                                                            "deployment_ids": ["1"]}}),
}  # fmt: skip
"""The pages only a platform's launch or registration reaches, rendered from their templates with what those
give them, on the service's origin (its stylesheet applied) with their scripts held back (they would post
on to the platform)."""


@pytest.mark.parametrize("name", list(LTI_PAGES))
def test_the_pages_of_lti_launches_pass_wcag_a_and_aa(chromium: Any, service: Service, name: str) -> None:
    template, context = LTI_PAGES[name]
    html = templates.get_template(template).render({**context, "session_query": ""})
    page = chromium.new_page()
    try:
        page.route("**/*.js", lambda route: route.abort())
        page.goto(service.process.url + "/ui/static/style.css")
        page.set_content(html)
        assert page.eval_on_selector("main", "main => getComputedStyle(main).maxWidth") == "960px"
        assert_accessible(page, name)
    finally:
        page.close()


def test_the_check_html_report_passes_wcag_a_and_aa(chromium: Any, service: Service, tmp_path: Path) -> None:
    report = Report.model_validate(service.report)
    page_path = tmp_path / "report.html"
    page_path.write_text(render_html(report, load_config()), encoding="utf-8")
    _assert_file_accessible(chromium, page_path, "the check --html report")


def test_the_class_report_passes_wcag_a_and_aa_its_links_24_pixels(
    chromium: Any, service: Service, tmp_path: Path
) -> None:
    report = Report.model_validate(service.report)
    entries = [
        ClassEntry("ada", report=report, report_href="ada.json"),
        ClassEntry("grace", report=report, late=True, report_href="grace.json"),
        ClassEntry("alan", name="Alan", status="missing"),
    ]
    page_path = tmp_path / "class.html"
    write_class_report(page_path, entries, title="RL 2026")
    sizes = _assert_file_accessible(chromium, page_path, "the class report")
    assert sizes and all(width >= 24 and height >= 24 for width, height in sizes), sizes


def test_the_similarity_page_passes_wcag_a_and_aa(chromium: Any, tmp_path: Path) -> None:
    reference = SIMILARITY_CORPUS / "references" / "public_2021"
    argv = ["similarity", str(SIMILARITY_CORPUS / "class"), "--reference", str(reference),
            "--out", str(tmp_path / "out"), "--cache", str(tmp_path / "cache")]  # fmt: skip
    assert main(argv) == 0
    _assert_file_accessible(chromium, tmp_path / "out" / "similarity.html", "the similarity page")


def test_axe_core_finds_what_the_rules_forbid(chromium: Any, tmp_path: Path) -> None:
    """The checks above can fail: an image without text, an unlabelled field, grey on grey and a 10-pixel link
    are each found."""
    page_path = tmp_path / "broken.html"
    page_path.write_text(
        '<!doctype html><html lang="en"><head><title>broken</title></head><body><main><h1>Broken</h1>'
        '<img src="data:image/gif;base64,R0lGODlhAQABAAAAACw="><input name="x">'
        '<p style="color:#aaa;background:#bbb">faint</p>'
        '<p><a href="#a" style="font-size:8px">a</a><a href="#b" style="font-size:8px">b</a></p>'
        "</main></body></html>",
        encoding="utf-8",
    )
    page = chromium.new_page()
    try:
        page.goto(page_path.as_uri())
        found = {violation["id"] for violation in axe_violations(page)}
    finally:
        page.close()
    assert {"image-alt", "label", "color-contrast", "target-size"} <= found, found


def _assert_file_accessible(chromium: Any, page_path: Path, what: str) -> list[tuple[float, float]]:
    """Open a written page and assert it; the sizes of its links (width, height in CSS pixels)."""
    page = chromium.new_page()
    requests: list[str] = []
    page.on("request", lambda request: requests.append(request.url))
    try:
        page.goto(page_path.as_uri())
        assert_accessible(page, what)
        # axe-core came with the package: nothing but the page itself (and its data: images) was fetched
        assert [url for url in requests if not url.startswith("data:")] == [page_path.as_uri()], requests
        sizes: list[list[float]] = page.eval_on_selector_all(
            "a[href]",
            "links => links.map(link => link.getBoundingClientRect()).map(box => [box.width, box.height])",
        )
    finally:
        page.close()
    return [(width, height) for width, height in sizes]
