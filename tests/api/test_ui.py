"""The web pages: sign-in, upload, live status, report with plots, everything escaped."""

from __future__ import annotations

import re
import time
from pathlib import Path

import pytest
from api_testing import INSTRUCTOR_TOKEN, SettingsFactory, add_student
from fake_grader import held, release
from fastapi.testclient import TestClient

from api.main import create_app

SOLUTION = b"def random_blackjack(n):\n    return 0.3\n\ndef blackjack(n=11):\n    return 0.4\n"
GRADING_WAIT_SECONDS = 60
BLACKJACK_PLOT = "Blackjack win rate against n"
FIGURE = r'<figure class="figure"><img src="data:image/png;base64,[A-Za-z0-9+/=]+" alt="([^"]+)">'


def _sign_in(client: TestClient, token: str) -> None:
    response = client.post("/ui/sign-in", data={"token": token}, follow_redirects=False)
    assert response.status_code == 303
    assert "httponly" in response.headers["set-cookie"].lower()
    assert "samesite=strict" in response.headers["set-cookie"].lower()


def test_signed_out_visitors_see_the_sign_in_form(client: TestClient) -> None:
    response = client.get("/")
    assert response.status_code == 200
    assert 'id="sign-in"' in response.text
    assert "script-src 'self'" in response.headers["content-security-policy"]


def test_a_wrong_token_is_refused_on_the_page(client: TestClient) -> None:
    response = client.post("/ui/sign-in", data={"token": "gg_wrong"})
    assert response.status_code == 401
    assert "the token sent belongs to nobody" in response.text


@pytest.mark.parametrize(
    "path",
    ["/ui/submissions/1", "/ui/submissions/1/live", "/ui/gradebook.csv"],
    ids=["page", "live", "gradebook"],
)
def test_signed_out_pages_answer_401_in_html(client: TestClient, path: str) -> None:
    response = client.get(path)
    assert response.status_code == 401
    assert response.headers["content-type"].startswith("text/html")
    assert "you are signed out" in response.text


def test_hostile_names_are_escaped_on_every_page(client: TestClient) -> None:
    student = "<img src=x onerror=alert(1)>"
    token = add_student(client, student)
    _sign_in(client, token)
    response = client.post(
        "/ui/submissions", files={"file": ("<svg onload=alert(1)>.py", SOLUTION)}, follow_redirects=False
    )
    assert response.status_code == 303
    page = client.get(response.headers["location"]).text
    home = client.get("/").text
    for html in (page, home):
        assert "<img src=x" not in html and "<svg onload" not in html
    assert "&lt;img src=x onerror=alert(1)&gt;" in home


def test_a_bad_upload_from_the_page_shows_the_reason(client: TestClient) -> None:
    _sign_in(client, add_student(client, "ada"))
    response = client.post("/ui/submissions", files={"file": ("notes.txt", b"hello")})
    assert response.status_code == 422
    assert "expected a Python file named like opengym.py" in response.text


def test_the_instructor_sees_everyone_and_the_gradebook_link(client: TestClient) -> None:
    add_student(client, "ada")
    _sign_in(client, INSTRUCTOR_TOKEN)
    home = client.get("/").text
    assert "All submissions" in home and 'href="/ui/gradebook.csv"' in home
    assert client.get("/ui/gradebook.csv").text.startswith("student,submission_id")
    assert client.post("/ui/submissions", files={"file": ("a.py", SOLUTION)}).status_code == 403


@pytest.mark.slow  # a grading through the sandbox
def test_upload_then_watch_the_checks_complete(make_settings: SettingsFactory, tmp_path: Path) -> None:
    settings = make_settings(workers=1)
    hold = tmp_path / "release"
    with TestClient(create_app(settings)) as client:
        _sign_in(client, add_student(client, "ada"))
        upload = client.post(
            "/ui/submissions",
            files={"file": ("opengym.py", held(hold, before="cartpole") + SOLUTION)},
            follow_redirects=False,
        )
        page_url = upload.headers["location"]
        page = client.get(page_url).text
        assert 'data-src="' + page_url + '/live"' in page and 'data-final="false"' in page
        seen_statuses = set()
        figures_while_running: set[str] = set()
        # The grading is held before cartpole until the page shows it running with blackjack's plot (the
        # event); then it may finish. The deadline bounds a hang only.
        deadline = time.monotonic() + GRADING_WAIT_SECONDS
        live = ""
        while 'data-final="true"' not in live and time.monotonic() < deadline:
            live = client.get(page_url + "/live").text
            status = re.search(r"Status: (\w+)", live).group(1)  # type: ignore[union-attr]
            seen_statuses.add(status)
            if status == "running":
                figures_while_running.update(re.findall(FIGURE, live))
                if BLACKJACK_PLOT in figures_while_running:
                    release(hold)
            time.sleep(0.1)
        assert "Score: 2 / 3" in live
        assert "running" in seen_statuses, "the live fragment should show the grading while it runs"
        assert figures_while_running == {BLACKJACK_PLOT}, "a finished problem's plot shows early"
        assert re.findall(FIGURE, live) == [BLACKJACK_PLOT], "the report's plot, drawn as the HTML report's"
        assert "<svg" not in live
        assert "&lt;output of blackjack&gt;" in live


def test_a_notebook_report_lists_what_was_skipped_and_shows_its_figures() -> None:
    from types import SimpleNamespace

    from api.web import templates
    from grader.submission.notebook import NotebookSummary, SkippedCode

    notebook = NotebookSummary(
        code_cells=3,
        kept_statements=4,
        skipped=[
            SkippedCode(cell=2, execution_count=5, line=1, reason="shell command", code="!pip install gym")
        ],
    )
    report = {
        "score": 0.0, "max_score": 1.0, "submission_error": None, "notebook": notebook.model_dump(),
        "submission": "lab.ipynb", "sha256": "0" * 64, "seed": 0, "gymnasium_version": "1.4.0",
        "grader_version": "0.1.0",
        "problems": [{"id": "taxi", "title": "Problem 5", "status": "failed", "score": 0.0, "max_score": 1.0,
                      "feedback": "off", "measurements": {
                          "returned_random_mean": -700.0, "exact_random_mean": -771.09,
                          "random_tolerance": 4.98, "returned_q_mean": 7.93, "exact_q_mean": 7.93,
                          "q_tolerance": 0.127}}],
    }  # fmt: skip
    submission = SimpleNamespace(status="done", report=report, progress=[], error=None)
    live = templates.get_template("_live.html").render(submission=submission, final=True)
    assert "<code>!pip install gym</code></td><td>shell command</td>" in live
    assert live.count('<img src="data:image/png;base64,') == 1 and 'alt="Taxi average returns"' in live
