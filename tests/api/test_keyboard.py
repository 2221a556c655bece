"""Keyboard alone (Tab, Enter and Space; no mouse, no click) signs in, uploads, reads a report and records an
override, on a real service in Chromium."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from accessibility import CHROMIUM, CHROMIUM_ARGS, tab_to
from api_testing import INSTRUCTOR_TOKEN
from live_server import E2E_GRADER, PARTIAL_SOLUTION, LiveProcess, create_student, service_environment

pytestmark = [pytest.mark.browser, pytest.mark.e2e, pytest.mark.sandbox]

SCORE_WAIT_MS = 120_000


@pytest.fixture
def server(tmp_path: Path) -> Iterator[LiveProcess]:
    process = LiveProcess(
        "serve", service_environment(tmp_path / "data", E2E_GRADER, workers=1), tmp_path / "log"
    )
    process.start()
    yield process
    process.stop()


def _sign_in(page: Any, url: str, token: str) -> None:
    page.goto(url + "/")
    tab_to(page, "#token")
    page.keyboard.type(token)
    page.keyboard.press("Enter")


def test_keyboard_alone_signs_in_uploads_reads_the_report_and_records_an_override(
    server: LiveProcess, tmp_path: Path
) -> None:
    if shutil.which(CHROMIUM) is None:
        pytest.skip(f"Chromium is not installed at {CHROMIUM} (apt-get install -y chromium)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="pip install playwright")
    token = create_student(server.url, "ada")
    solution = tmp_path / "opengym.py"
    solution.write_bytes(PARTIAL_SOLUTION)
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
        try:
            student = browser.new_page()
            _sign_in(student, server.url, token)
            student.wait_for_selector("#upload")
            tab_to(student, "#file")
            with student.expect_file_chooser() as chooser:
                student.keyboard.press("Space")
            chooser.value.set_files(str(solution))
            tab_to(student, "#upload button[type=submit]")
            student.keyboard.press("Enter")
            student.wait_for_url("**/ui/submissions/*")
            submission_path = student.url.removeprefix(server.url)
            student.wait_for_selector("#score", timeout=SCORE_WAIT_MS)
            assert student.inner_text("#score") == "Score: 3 / 5"
            # Reading the report: a problem's measurements open from the keyboard.
            details = "#problem-cartpole details"
            tab_to(student, f"{details} > summary")
            student.keyboard.press("Enter")
            assert student.eval_on_selector(details, "element => element.open") is True
            assert student.locator(f"{details} table.measurements").is_visible()
            # Back to the list, and the report again through its link.
            tab_to(student, "header a.brand")
            student.keyboard.press("Enter")
            student.wait_for_selector("#upload")
            tab_to(student, f'a[href="{submission_path}"]')
            student.keyboard.press("Enter")
            student.wait_for_url("**" + submission_path)
            student.wait_for_selector("#score")

            instructor = browser.new_context().new_page()
            _sign_in(instructor, server.url, INSTRUCTOR_TOKEN)
            instructor.wait_for_selector("#override")
            for field, value in (
                ("#override-student", "ada"),
                ("#override-problem", "blackjack"),
                ("#override-points", "1"),
                ("#override-reason", "graded by hand: the threshold is right"),
            ):
                tab_to(instructor, field)
                instructor.keyboard.type(value)
            tab_to(instructor, "#override button[type=submit]")
            instructor.keyboard.press("Space")
            instructor.wait_for_selector("#override-result")
            assert instructor.inner_text("#override-result") == (
                "blackjack of ada set to 1: graded by hand: the threshold is right"
            )
            student.reload()
            student.wait_for_selector("#overrides")
            assert "graded by hand: the threshold is right" in student.inner_text("#overrides")
        finally:
            browser.close()


def test_keyboard_alone_creates_a_course_and_its_first_instructor(server: LiveProcess) -> None:
    if shutil.which(CHROMIUM) is None:
        pytest.skip(f"Chromium is not installed at {CHROMIUM} (apt-get install -y chromium)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="pip install playwright")
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
        try:
            operator = browser.new_page()
            _sign_in(operator, server.url, INSTRUCTOR_TOKEN)
            operator.wait_for_selector("#override")
            tab_to(operator, "#nav-courses")
            operator.keyboard.press("Enter")
            operator.wait_for_selector("#new-course")
            for field, value in (
                ("#course-slug", "rl-2026"),
                ("#course-title", "Reinforcement learning 2026"),
            ):
                tab_to(operator, field)
                operator.keyboard.type(value)
            operator.keyboard.press("Enter")
            operator.wait_for_url("**/ui/courses/rl-2026")
            tab_to(operator, "#staff-name")
            operator.keyboard.type("Grace Hopper")
            tab_to(operator, "#new-staff button[type=submit]")
            operator.keyboard.press("Enter")
            operator.wait_for_selector("#staff-token")
            token = operator.inner_text("#staff-token")

            instructor = browser.new_context().new_page()
            _sign_in(instructor, server.url, token)
            instructor.wait_for_url("**/ui/courses")
            tab_to(instructor, 'a[href="/ui/courses/rl-2026"]')
            instructor.keyboard.press("Enter")
            instructor.wait_for_selector("#new-assignment")
            for field, value in (("#assignment-slug", "lab-2"), ("#assignment-title", "Policy iteration")):
                tab_to(instructor, field)
                instructor.keyboard.type(value)
            tab_to(instructor, "#assignment-edition")
            instructor.keyboard.type("v2026")  # a select is chosen by typing its option's first letters
            tab_to(instructor, "#new-assignment button[type=submit]")
            instructor.keyboard.press("Space")
            instructor.wait_for_selector("#course-notice")
            assert "v2026" in instructor.inner_text("#assignment-lab-2")
        finally:
            browser.close()
