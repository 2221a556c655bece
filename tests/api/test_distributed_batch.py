"""`gymgrade grade` on the cluster: a real redis-server and `gymgrade worker`, the fake grader (and once
the real grader, through the real sandbox under full isolation).

The batch core is the local one (tests/grader/grading/test_batch.py); these tests pin that the cluster's
executor hands every report back, that a re-run resumes, that an interrupted batch keeps what it finished,
and that a class zip's files are named as a local grading names them (the request's names untrusted).
"""

from __future__ import annotations

import base64
import csv
import io
import json
import re
import threading
import time
import uuid
import zipfile
from collections.abc import Iterator
from pathlib import Path

import pytest
from api_testing import FAKE_GRADER, RedisServer
from live_server import LiveProcess, service_environment

from api.jobs.batch import CeleryExecutor, executor_from_environment
from api.settings import BrokerSettings
from grader import cli
from grader.classroom import command
from grader.errors import BatchInterrupted, ExecutorUnavailable
from grader.grading.batch import grade_many
from grader.render.neutral import file_name
from grader.report import ProblemResult
from grader.sandbox import IsolationPolicy

pytestmark = pytest.mark.e2e

ONLY = "random_blackjack,blackjack,cartpole"  # the fake grader's problems
READY_SECONDS = 60.0


@pytest.fixture
def worker_tmp(tmp_path: Path) -> Path:
    """The worker's temporary folder (its TMPDIR): where its gradings' scratch folders are made."""
    folder = tmp_path / "worker-tmp"
    folder.mkdir()
    return folder


@pytest.fixture
def broker_url(tmp_path: Path, redis_server: RedisServer, worker_tmp: Path) -> Iterator[str]:
    """A Redis database served by one `gymgrade worker` (SQLite for its unused job rows)."""
    url = redis_server.new_url()
    env = service_environment(tmp_path / "data", FAKE_GRADER, broker_url=url, allow_weak_isolation=1, nice=0)
    env["TMPDIR"] = str(worker_tmp)
    worker = LiveProcess("worker", env, tmp_path / "worker.log").start(wait_for_http=False)
    deadline = time.monotonic() + READY_SECONDS
    while not re.search(r"gymgrade-\d+@\S+ ready", worker.log()):
        assert time.monotonic() < deadline, worker.log()
        time.sleep(0.1)
    yield url
    worker.stop()


@pytest.fixture
def inputs(tmp_path: Path) -> Path:
    folder = tmp_path / "inputs"
    folder.mkdir()
    (folder / "alice.py").write_text("def random_blackjack(n):\n    return n\n")
    (folder / "bob.py").write_text("def cartpole():\n    return 1\n")
    (folder / "carol.py").write_text("def car(:\n")
    return folder


def _use_cluster(monkeypatch: pytest.MonkeyPatch, broker_url: str) -> None:
    class ClusterEntryPoint:
        name = "cluster"

        def load(self) -> object:
            return executor_from_environment

    monkeypatch.setenv("GYMGRADE_BROKER_URL", broker_url)
    monkeypatch.setattr(
        command,
        "entry_points",
        lambda group: [ClusterEntryPoint()] if group == command.EXECUTOR_GROUP else [],
    )


def test_a_batch_on_the_cluster_keeps_every_report_and_resumes(
    tmp_path: Path,
    broker_url: str,
    inputs: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    _use_cluster(monkeypatch, broker_url)
    out = tmp_path / "out"
    argv = ["grade", str(inputs), "--out", str(out), "--only", ONLY, "--allow-weak-isolation"]
    assert cli.main(argv) == 0
    err = capsys.readouterr().err
    assert f"Grading on the Celery cluster at {broker_url}." in err
    rows = list(csv.DictReader((out / "grades.csv").open()))
    assert [(row["student"], row["total"]) for row in rows] == [
        ("alice", "1"),
        ("bob", "1"),
        ("carol", "0"),
    ]
    assert rows[2]["note"].startswith("carol.py is not valid Python")

    (inputs / "bob.py").write_text("def cartpole():\n    return 2\n\ndef blackjack(n):\n    return n\n")
    assert cli.main(argv) == 0
    err = capsys.readouterr().err
    assert f"Resuming in {out}: 2 of 3 submissions are already graded there" in err
    assert "bob: blackjack passed" in err and "alice:" not in err.split("grading 1.")[1]
    rows = list(csv.DictReader((out / "grades.csv").open()))
    assert [(row["student"], row["total"]) for row in rows] == [
        ("alice", "1"),
        ("bob", "2"),
        ("carol", "0"),
    ]


def test_an_interrupted_cluster_batch_keeps_what_it_finished(
    tmp_path: Path, broker_url: str, inputs: Path
) -> None:
    paths = sorted(inputs.glob("*.py"))
    executor = CeleryExecutor(BrokerSettings(broker_url=broker_url), IsolationPolicy.ALLOW_FALLBACK)
    seen: list[str] = []

    def stop_at_the_second_file(path: Path, result: ProblemResult) -> None:
        seen.append(path.name)
        if len(set(seen)) == 2:
            raise KeyboardInterrupt

    out = tmp_path / "out"
    with pytest.raises(BatchInterrupted) as interrupted:
        grade_many(paths, out, only=ONLY.split(","), executor=executor, on_result=stop_at_the_second_file)
    assert (interrupted.value.finished, interrupted.value.total) == (1, 3)
    outcome = grade_many(paths, out, only=ONLY.split(","), executor=executor)
    assert len(outcome.reused) == 1 and len(outcome.graded) == 2
    assert [report.score for report in outcome.reports] == [1.0, 1.0, 0.0]


BROKEN = b"def random_blackjack(n):\n    return (\n"
BROKEN_ENTRY = "smithjohn_3001_7001_policy_iteration-1.py"
HONEST_ENTRY = "leeann_3003_7003_opengym.py"
HOSTILE_FILE = "=cmd|' -C calc'!A0\x1b]0;owned\x07\u202egpj\r\n" + "x" * 500 + ".py"
HOSTILE_ZIP = "mallory_3004_7004_lab.zip"
"""A student's own zip in the download, holding a file named ``HOSTILE_FILE`` (a formula start, an escape
sequence, a bidi override, a line break, 500 characters)."""
DUE = "2026-03-01T23:59:00+00:00"


def _canvas_zip(path: Path, *, honest: bool = True) -> Path:
    path.parent.mkdir(parents=True)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as bundle:
        bundle.writestr(BROKEN_ENTRY, BROKEN)
        if honest:
            bundle.writestr(HONEST_ENTRY, b"def random_blackjack(n):\n    return n\n")
        inner = io.BytesIO()
        with zipfile.ZipFile(inner, "w") as own:
            own.writestr(HOSTILE_FILE, BROKEN)
        bundle.writestr(HOSTILE_ZIP, inner.getvalue())
    return path


def test_a_class_zip_graded_on_the_cluster_names_its_files_as_a_local_grading_does(
    tmp_path: Path,
    broker_url: str,
    worker_tmp: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The zip is read into numbered files (0.py...); the report's ``submission``, a broken file's message
    and the gradebook's note name each file as the download does, as a local grading of the class does
    (of its broken files, refused before any sandbox: the real grader's names, at no cost)."""
    options = ["--only", ONLY, "--seed", "5", "--allow-weak-isolation", "--due", DUE]
    broken_only = _canvas_zip(tmp_path / "local-download" / "submissions.zip", honest=False)
    assert cli.main(["grade", str(broken_only), "--out", str(tmp_path / "local"), *options]) == 0
    local = {path.stem: json.loads(path.read_text("utf-8")) for path in (tmp_path / "local").glob("*.json")}
    _use_cluster(monkeypatch, broker_url)
    download = _canvas_zip(tmp_path / "download" / "submissions.zip")
    out = tmp_path / "out"
    assert cli.main(["grade", str(download), "--out", str(out), *options]) == 0
    assert f"Grading on the Celery cluster at {broker_url}." in capsys.readouterr().err
    cluster = {path.stem: json.loads(path.read_text("utf-8")) for path in out.glob("*.json")}

    hostile = file_name(f"{HOSTILE_ZIP}/{HOSTILE_FILE}")
    assert hostile.startswith("'=cmd|' -C calc'!A0\ufffd]0;owned\ufffd\ufffdgpj x") and hostile.endswith("…")
    expected = {"3001": BROKEN_ENTRY, "3003": HONEST_ENTRY, "3004": hostile}
    assert {identity: report["submission"] for identity, report in cluster.items()} == expected
    assert {identity: report["submission"] for identity, report in local.items()} == {
        identity: expected[identity] for identity in ("3001", "3004")
    }
    for identity in ("3001", "3004"):  # the message names the file alike (its wording is each grader's)
        shown = expected[identity]
        assert str(cluster[identity]["submission_error"]).startswith(f"{shown} is not valid Python: ")
        assert str(local[identity]["submission_error"]).startswith(f"{shown} is not valid Python: ")
    assert cluster["3003"]["score"] == 1.0
    rows = {row["student"]: row for row in csv.DictReader((out / "grades.csv").open(encoding="utf-8"))}
    assert BROKEN_ENTRY in rows["3001"]["note"]
    for report in cluster.values():  # never the numbered copies (0.py...) nor the worker's submission.py
        text = json.dumps(report)
        assert not re.search(r"(?<![\w-])(\d+|submission)\.py", text), text
    written = [path.name for path in tmp_path.rglob("*") if not path.is_relative_to(tmp_path / "download")]
    assert not [name for name in written if "cmd" in name or "owned" in name or len(name) > 100], written
    assert list(worker_tmp.iterdir()) == [], "every grading's scratch folder is removed"


def _send_raw(broker_url: str, request: dict[str, object]) -> dict[str, object]:
    """Send one ``gymgrade.grade_file`` request as any client could, and wait for its reply."""
    from api.jobs.distributed import GRADE_FILE, QUEUE, make_celery, redis_client

    settings = BrokerSettings(broker_url=broker_url)
    app, client = make_celery(settings), redis_client(settings)
    reply_to = f"gymgrade:batch:test-{uuid.uuid4().hex}"
    try:
        app.send_task(GRADE_FILE, args=[{"key": "0", "reply_to": reply_to, **request}], queue=QUEUE)
        item = client.blpop([reply_to], timeout=READY_SECONDS)  # bounds a hang only: a reply ends it
        assert item is not None, "the worker sent no reply"
        reply: dict[str, object] = json.loads(item[1])
        return reply
    finally:
        client.close()
        app.close()


CLIMBING_NAME = "../../../" + HOSTILE_FILE
LONG_FILENAME = "a" * 5_000 + ".py"


@pytest.mark.parametrize(
    ("filename", "name", "shown"),
    [
        ("3.py", BROKEN_ENTRY, BROKEN_ENTRY),
        ("../../evil.py", CLIMBING_NAME, file_name(HOSTILE_FILE)),
        (LONG_FILENAME, "=cmd.py", "'=cmd.py"),
        ("../../evil.py", None, "evil.py"),
        ("3.py", 12, "3.py"),
    ],
    ids=["lms-name", "climbing-hostile-name", "formula-and-long-filename", "no-name-field", "name-not-text"],
)
def test_a_workers_request_names_are_untrusted_shown_neutralised_never_a_path(
    tmp_path: Path, broker_url: str, worker_tmp: Path, filename: str, name: object, shown: str
) -> None:
    """Whatever a request says, the worker shows its ``name`` (or, from a client of before the field, its
    ``filename``) as ``file_name`` shows it, and writes the file in its scratch under a safe name only."""
    held = tmp_path / "release"
    request: dict[str, object] = {
        "filename": filename,
        "seed": 3,
        "only": ONLY.split(","),
        "config_toml": None,
        "allow_weak_isolation": True,
    }
    if name is not None:
        request["name"] = name
    holding = f"# fake-grader: hold={held}\ndef cartpole():\n    return 1\n".encode()
    replies: list[dict[str, object]] = []
    sender = threading.Thread(
        target=lambda: replies.append(_send_raw(broker_url, {**request, "content": _base64(holding)}))
    )
    sender.start()
    try:
        deadline = time.monotonic() + READY_SECONDS  # bounds a hang only: the file's arrival ends the loop
        while not list(worker_tmp.glob("gymgrade-job-*/submission/*")):
            assert time.monotonic() < deadline and sender.is_alive(), replies
            time.sleep(0.05)
        (scratch,) = worker_tmp.glob("gymgrade-job-*")
        during = sorted(str(path.relative_to(worker_tmp)) for path in worker_tmp.rglob("*"))
    finally:
        held.touch()
        sender.join()
    job = scratch.name
    assert during == [job, f"{job}/grader-stderr.log", f"{job}/submission", f"{job}/submission/submission.py"]
    graded = replies[0]["report"]
    assert isinstance(graded, dict) and graded["submission"] == shown
    broken = _send_raw(broker_url, {**request, "content": _base64(BROKEN)})["report"]
    assert isinstance(broken, dict) and broken["submission"] == shown
    assert str(broken["submission_error"]).startswith(f"{shown} is not valid Python: ")
    assert list(worker_tmp.iterdir()) == [], "every grading's scratch folder is removed"
    assert not [path for path in tmp_path.rglob("*") if "evil" in path.name or "cmd" in path.name]


def _base64(data: bytes) -> str:
    return base64.b64encode(data).decode("ascii")


def test_an_unreachable_broker_is_refused_with_a_remedy(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GYMGRADE_BROKER_URL", "redis://127.0.0.1:1/0")
    with pytest.raises(
        ExecutorUnavailable,
        match=r"cannot reach the Redis broker at redis://127.0.0.1:1/0 .*unset GYMGRADE_BROKER_URL",
    ):
        executor_from_environment(IsolationPolicy.REQUIRE_FULL)
    monkeypatch.delenv("GYMGRADE_BROKER_URL")
    assert executor_from_environment(IsolationPolicy.REQUIRE_FULL) is None


def test_a_file_the_cluster_could_not_grade_is_a_grader_error_in_every_problem(tmp_path: Path) -> None:
    from api.jobs.batch import _report
    from grader.grading.plan import GradingPlan

    path = tmp_path / "alice.py"
    path.write_bytes(b"def car():\n    return 1\n")
    plan = GradingPlan.load(None, ["cartpole", "car"])
    report = _report(path, path.read_bytes(), {"error": "the worker was killed"}, plan, 7)
    assert (report.submission, report.seed, report.score) == ("alice.py", 7, 0.0)
    assert [(result.id, result.status) for result in report.problems] == [
        ("cartpole", "error"),
        ("car", "error"),
    ]
    assert report.grader_errors == [
        "cartpole: the cluster could not grade it: the worker was killed",
        "car: the cluster could not grade it: the worker was killed",
    ]
    assert "not your code's fault" in report.problems[0].feedback


def test_the_workers_are_sent_the_configuration_the_batch_checked(tmp_path: Path) -> None:
    from api.jobs.batch import configuration_text
    from grader.errors import ConfigError
    from grader.grading.plan import GradingPlan
    from grader.lab.assignment import DEFAULT_CONFIG_PATH

    bundled = DEFAULT_CONFIG_PATH.read_text(encoding="utf-8")
    config = tmp_path / "assignment.toml"
    config.write_text(bundled, encoding="utf-8")
    plan = GradingPlan.load(config, None)
    assert configuration_text(plan) == bundled
    assert configuration_text(GradingPlan.load(None, None)) is None
    config.write_text("# the same configuration, with a comment\n" + bundled, encoding="utf-8")
    assert configuration_text(plan) is not None  # the same configuration: sent as the file now reads
    edited = bundled.replace("[problems.car]\npoints = 1.0", "[problems.car]\npoints = 4.0")
    assert edited != bundled
    config.write_text(edited, encoding="utf-8")
    with pytest.raises(ConfigError, match="changed after the batch read it"):
        configuration_text(plan)
    config.write_text("[problems.car\n", encoding="utf-8")
    with pytest.raises(ConfigError, match="cannot read the assignment configuration"):
        configuration_text(plan)


ROOT = Path(__file__).resolve().parents[2]


RAISES_ENTRY = "raiserosa_3005_7005_opengym-2.py"
MISTAKEN_ENTRY = "bobby_3002_7002_opengym (1).py"
CALL_RAISES_ENTRY = "calla_3006_7006_opengym-3.py"
FOLDER_ENTRY = "opengym (2).py"
"""A folder download's file, graded under its own name, which the sandbox's copy would spell otherwise."""


@pytest.mark.slow
@pytest.mark.sandbox
def test_a_real_worker_grades_through_the_real_sandbox(tmp_path: Path, redis_server: RedisServer) -> None:
    """The cluster with the real grader: a `gymgrade worker` on the service's default grader, full isolation
    required, one cheap problem; the honest file passes and the mistaken one fails with its diagnosis. Each
    file is shown by a class download's name (a file raising at import is named in the sandbox's traceback,
    a broken one by the grader's validation), and every report is the one a local grading of the same files,
    names and seed gives, but for its timings (``Report.graded_view``)."""
    from grader.sandbox import probe_isolation

    isolation = probe_isolation()
    if not isolation.full:
        pytest.skip("needs full isolation:\n" + isolation.summary())
    url = redis_server.new_url()
    real_grader = "grader.grading.grade:grade_submission"
    env = service_environment(tmp_path / "data", real_grader, broker_url=url, allow_weak_isolation=0, nice=0)
    worker = LiveProcess("worker", env, tmp_path / "worker.log").start(wait_for_http=False)
    inputs = tmp_path / "inputs"
    inputs.mkdir()
    honest = (ROOT / "submissions" / "classic_complete.py").read_bytes()
    mistaken = (ROOT / "submissions" / "mistakes" / "random_blackjack_average_reward.py").read_bytes()
    (inputs / "0.py").write_bytes(honest)
    (inputs / "1.py").write_bytes(mistaken)
    (inputs / "2.py").write_bytes(b"raise RuntimeError('boom at import')\n")
    (inputs / "3.py").write_bytes(BROKEN)
    (inputs / "4.py").write_bytes(b"def random_blackjack(n):\n    raise ValueError('no games today')\n")
    (inputs / FOLDER_ENTRY).write_bytes(b"raise RuntimeError('boom at import')\n")
    paths = sorted(inputs.glob("*.py"))
    shown = [HONEST_ENTRY, MISTAKEN_ENTRY, RAISES_ENTRY, file_name(HOSTILE_FILE), CALL_RAISES_ENTRY]
    file_names = dict(zip(paths, shown, strict=False))  # a folder's file keeps its own name: none given
    shown.append(FOLDER_ENTRY)
    try:
        deadline = time.monotonic() + READY_SECONDS  # bounds a hang only: the loop ends at the log's "ready"
        while not re.search(r"gymgrade-\d+@\S+ ready", worker.log()):
            assert time.monotonic() < deadline, worker.log()
            time.sleep(0.1)
        executor = CeleryExecutor(BrokerSettings(broker_url=url), IsolationPolicy.REQUIRE_FULL)
        outcome = grade_many(
            paths,
            tmp_path / "out",
            seed=11,
            only=["random_blackjack"],
            executor=executor,
            file_names=file_names,
        )
    finally:
        worker.stop()

    ada, bob, rosa, broken, calling, folder = outcome.reports
    assert (ada.grader_errors, bob.grader_errors, rosa.grader_errors) == ([], [], []), worker.log()
    assert ada.isolation is not None and ada.isolation.full, worker.log()
    assert [(result.id, result.status) for result in ada.problems] == [("random_blackjack", "passed")]
    assert [(result.id, result.status) for result in bob.problems] == [("random_blackjack", "failed")]
    assert "it equals the average reward" in bob.problems[0].feedback
    assert [report.submission for report in outcome.reports] == shown
    assert f"importing {RAISES_ENTRY} raised RuntimeError: boom at import" in rosa.problems[0].feedback
    assert f'File "/submission/{RAISES_ENTRY}", line 1, in <module>' in rosa.problems[0].feedback
    assert str(broken.submission_error).startswith(f"{shown[3]} is not valid Python: ")
    assert (
        f'File "/submission/{CALL_RAISES_ENTRY}", line 2, in random_blackjack' in calling.problems[0].feedback
    )
    assert "served the classic gym API" in json.dumps(ada.graded_view())
    assert f'File "/submission/{FOLDER_ENTRY}", line 1, in <module>' in folder.problems[0].feedback
    for report in outcome.reports:  # never the numbered copies (0.py...) nor the worker's submission.py
        assert not re.search(r"(?<![\w-])(\d+|submission)\.py", json.dumps(report.graded_view())), report
    local = grade_many(paths, tmp_path / "local", seed=11, only=["random_blackjack"], file_names=file_names)
    assert [report.graded_view() for report in outcome.reports] == [
        report.graded_view() for report in local.reports
    ]
