"""Gradescope: results.json per its schema, the choice of file, and the autograder zip run for real.

What students see of results.json is modelled by `student_sees`, after Gradescope's specification
(https://gradescope-autograders.readthedocs.io/en/latest/specs/): the tests whose visibility they may see, the
top-level score, output and time only when the results' own visibility allows, never ``extra_data`` (stored
only) nor stdout (``stdout_visibility`` hidden).
"""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
import unicodedata
import zipfile
from pathlib import Path
from typing import Any

import pytest
from gradescope_support import SECRET, metadata
from grading_support import ROOT, SUBMISSIONS, write_config

from grader.cli import main
from grader.cli.gradescope import SECRET_FILE, bundle, bundle_secret, pick_submission
from grader.errors import GradescopeError
from grader.lab.editions import EDITIONS
from grader.lab.problems import PROBLEM_IDS
from grader.render.gradescope import GradescopeResults, results
from grader.report import GradingTimings, ProblemResult, Report, Timings
from grader.seeds import upload_seed
from grader.submission.gradescope_upload import METADATA_FILE, UploadSeed, read_metadata


def student_sees(data: dict[str, Any], shown: frozenset[str] = frozenset({"visible"})) -> dict[str, Any]:
    """What Gradescope shows a student of results.json (see the module's docstring)."""
    whole = data.get("visibility", "visible") in shown
    return {
        "score": data["score"] if whole else None,
        "execution_time": data.get("execution_time") if whole else None,
        "output": data["output"] if whole else None,
        "tests": [test for test in data["tests"] if test.get("visibility", "visible") in shown],
    }


def _report(**fields: object) -> Report:
    problems = [
        ProblemResult(id="random_blackjack", title="Problem 1", status="passed", score=1, max_score=1,
                      feedback="fine"),
        ProblemResult(id="cartpole", title="Problem 3", status="timeout", score=0, max_score=1,
                      feedback="too slow", output="hello"),
    ]  # fmt: skip
    values: dict[str, object] = {
        "submission": "opengym.py", "sha256": "0", "seed": 3, "gymnasium_version": "1.4.0",
        "grader_version": "0.1.0", "score": 1.0, "max_score": 2.0, "problems": problems,
        "execution_time": 61.6,
    }  # fmt: skip
    values.update(fields)
    return Report.model_validate(values)


def test_a_report_becomes_one_gradescope_test_per_problem() -> None:
    graded = results(_report())
    data = json.loads(graded.to_json())
    assert (data["score"], data["execution_time"], data["visibility"]) == (1.0, 62, "visible")
    fields = ("name", "number", "score", "max_score", "status", "visibility")
    assert [tuple(test[field] for field in fields) for test in data["tests"]] == [
        ("Problem 1", "1", 1.0, 1.0, "passed", "visible"),
        ("Problem 3", "2", 0.0, 1.0, "failed", "visible"),
        ("Problem 3: what the code printed (instructor only)", "2.1", 0.0, 0.0, "passed", "hidden"),
    ]  # fmt: skip
    assert data["tests"][1]["output"] == (
        "timeout: too slow\n\nWhat your code printed is kept for your instructor, not shown here; "
        "run gymgrade check on your own machine to see it."
    )
    assert data["tests"][2]["output"] == "hello"
    assert data["output"].startswith("gymgrade 0.1.0, gymnasium 1.4.0.")
    assert "extra_data" not in data, "no seed recorded unless the upload's seed is given"
    assert "hello" not in json.dumps(student_sees(data)), "a file could print its starts"
    GradescopeResults.model_validate(data)


def test_the_upload_seed_is_recorded_for_the_instructor_only() -> None:
    upload = UploadSeed(8_913_374_620, "derived", ("gradescope", "77", "2026-11-25T10:00:00-08:00", "5"))
    data = json.loads(results(_report(), upload=upload).to_json())
    assert data["extra_data"] == {
        "gymgrade": {"seed": 8_913_374_620, "seed_source": "derived", "identity": list(upload.identity)}
    }
    (note,) = [test for test in data["tests"] if test["name"] == "Grading seed (instructor only)"]
    assert note["visibility"] == "hidden" and note["output"] == (
        "Grading seed 8913374620, derived from the bundle's secret and this upload "
        "(gradescope, 77, 2026-11-25T10:00:00-08:00, 5). Regrade it identically with: "
        "gymgrade gradescope-seed --bundle autograder.zip --metadata submission_metadata.json "
        "--submission FILE"
    )
    assert "8913374620" not in json.dumps(student_sees(data))


def _problem(problem_id: str, visibility: str, outcome: int) -> ProblemResult:
    """A problem whose every outcome-dependent field follows ``outcome``."""
    return ProblemResult.model_validate(
        {"id": problem_id, "title": f"Problem {problem_id}", "status": ["passed", "failed", "error"][outcome],
         "score": [1.0, 0.25, 0.0][outcome], "max_score": 1.0, "feedback": f"{problem_id} outcome {outcome}",
         "output": f"printed {outcome}" * outcome, "seed": 11, "visibility": visibility,
         "timings": Timings(wall_seconds=3.0 + outcome, student_seconds=1.0 + outcome, overhead_seconds=2.0)}
    )  # fmt: skip


def _withholding_report(visibility: str, outcome: int) -> Report:
    """Two visible problems and taxi, ``visibility``, whose outcome (and so its time, errors) varies."""
    problems = [
        _problem("cartpole", "visible", 0),
        _problem("car", "visible", 1),
        _problem("taxi", visibility, outcome),
    ]
    elapsed = 10.0 + 7 * outcome
    return _report(
        problems=problems,
        score=sum(problem.score for problem in problems),
        max_score=3.0,
        grader_errors=["taxi: the grader failed"] if outcome == 2 else [],
        execution_time=elapsed,
        timings=GradingTimings(elapsed_seconds=elapsed, workers=2, check_seconds=elapsed,
                               student_seconds=outcome, overhead_seconds=elapsed - outcome),
    )  # fmt: skip


@pytest.mark.parametrize(
    ("visibility", "shown", "withheld"),
    [
        ("hidden", frozenset({"visible"}), True),
        ("hidden", frozenset({"visible", "after_due_date"}), True),
        ("after_due_date", frozenset({"visible"}), True),
        ("after_due_date", frozenset({"visible", "after_due_date"}), False),
    ],
    ids=["hidden", "hidden-after-due-date", "after-due-date-before-it", "after-due-date-past-it"],
)
def test_nothing_a_student_sees_varies_with_a_withheld_problem(
    visibility: str, shown: frozenset[str], withheld: bool
) -> None:
    seen = [
        json.dumps(
            student_sees(json.loads(results(_withholding_report(visibility, outcome)).to_json()), shown)
        )
        for outcome in range(3)
    ]
    if withheld:
        assert seen[0] == seen[1] == seen[2], "a withheld problem's outcome shows through"
        data = json.loads(results(_withholding_report(visibility, 1)).to_json())
        assert (data["visibility"], data["score"], "execution_time" in data) == (visibility, 1.5, False)
        (about,) = [test for test in data["tests"] if test["name"] == "About this grading"]
        assert about["visibility"] == "visible"
        assert about["output"].endswith("The total score is shown when every problem's result is.")
    else:
        assert len(set(seen)) == 3, "once shown, the problem and the total are the student's"


def test_a_shown_problems_grader_error_stays_in_the_output() -> None:
    report = _withholding_report("hidden", 0).model_copy(
        update={"grader_errors": ["car: broke", "taxi: broke"]}
    )
    output = results(report).output
    assert "Grader error (not your fault): car: broke" in output and "taxi: broke" not in output


def test_a_skipped_problem_failed_nothing_and_says_it_was_not_run() -> None:
    skipped = ProblemResult(
        id="find_qvalues",
        title="find_qvalues",
        status="skipped",
        score=0,
        max_score=0,
        feedback="Not run: ...",
    )
    graded = results(_report(problems=[skipped], score=0.0, max_score=0.0))
    (test,) = graded.tests
    assert (test.status, test.score, test.max_score, test.output) == (
        "passed",
        0.0,
        0.0,
        "skipped: Not run: ...",
    )


def test_a_file_that_cannot_be_graded_says_why_in_the_output() -> None:
    graded = results(_report(submission_error="opengym.py is empty: nothing to grade."))
    assert "opengym.py is empty: nothing to grade." in graded.output


@pytest.mark.parametrize(
    ("files", "picked"),
    [
        (["opengym.py"], "opengym.py"),
        (["lab.ipynb", ".ipynb_checkpoints/lab-checkpoint.ipynb"], "lab.ipynb"),
        (["helper.py", "opengym.py", "notes.txt"], "opengym.py"),
        (["a.py", "b.py"], "Expected one Python file (.py) or Jupyter notebook (.ipynb) with your functions, "
         "ideally named opengym.py; found a.py, b.py. Submit exactly one such file."),
        ([], "Expected one Python file (.py) or Jupyter notebook (.ipynb) with your functions, ideally "
         "named opengym.py; found no .py or .ipynb file. Submit exactly one such file."),
        (["helper.py", "opengym.py -> /etc/hostname"], "opengym.py is a symbolic link (to /etc/hostname): "
         "links are never followed, so it was not read. Submit the file itself, not a link to it."),
        (["lab/opengym.py", "old -> lab"], "lab/opengym.py"),
        (["a.py", "b.py", "old -> lab"], "Expected one Python file (.py) or Jupyter notebook (.ipynb) with "
         "your functions, ideally named opengym.py; found a.py, b.py. Submit exactly one such file. old is a "
         "symbolic link (to lab): links are never followed, so it was not read. Submit the file itself, not "
         "a link to it."),
    ],
    ids=["one-file", "notebook-beside-checkpoint", "lab-name-among-several", "ambiguous", "nothing",
         "lab-name-is-a-link", "folder-link-not-walked", "folder-link-named"],
)  # fmt: skip
def test_the_graded_file_is_chosen_or_the_student_told(tmp_path: Path, files: list[str], picked: str) -> None:
    for name in files:
        name, _, target = name.partition(" -> ")
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        if target:
            (tmp_path / name).symlink_to(target)
        else:
            (tmp_path / name).write_text("x = 1\n")
    choice = pick_submission(tmp_path)
    assert (choice.relative_to(tmp_path).as_posix() if isinstance(choice, Path) else choice) == picked


def test_an_upload_is_walked_only_so_deep(tmp_path: Path) -> None:
    deep = tmp_path.joinpath(*["d"] * 40)
    deep.mkdir(parents=True)
    (deep / "opengym.py").write_text("x = 1\n")
    choice = pick_submission(tmp_path)
    assert isinstance(choice, str) and choice.endswith(f"{'d/' * 32}d is deeper than 32 folders: not read.")


NAME_LIKE_SECRET = "ab" * 32
"""A secret that parses as a Python name: run as a student's code, a NameError would print it."""


def _linked_upload(root: Path, kind: str) -> None:
    """A Gradescope root whose upload reaches for the bundle's secret: a symbolic link to it, a hard link,
    or a folder link to the bundle's source folder."""
    (root / "source").mkdir(parents=True)
    secret = root / "source" / SECRET_FILE
    secret.write_text(NAME_LIKE_SECRET + "\n")
    secret.chmod(0o644)  # as an unzip may leave it: the grader makes it private before grading
    (root / METADATA_FILE).write_text(json.dumps(metadata(3001, "2026-11-26T09:00:00.000000-08:00", 9)))
    upload = root / "submission"
    upload.mkdir()
    if kind == "symlink":
        (upload / "opengym.py").symlink_to(secret)
    elif kind == "relative-symlink":
        (upload / "opengym.py").symlink_to(Path("..") / "source" / SECRET_FILE)
    elif kind == "hard-link":
        os.link(secret, upload / "opengym.py")
    else:
        (upload / "lab").symlink_to(root / "source", target_is_directory=True)
        (upload / "notes.txt").write_text("my solution is in lab/\n")


LINKED = [
    ("symlink", "opengym.py is a symbolic link (to {root}/source/seed_secret): links are never followed, so it was not read. Submit the file itself, not a link to it."),  # noqa: E501
    ("relative-symlink", "opengym.py is a symbolic link (to ../source/seed_secret): links are never followed"),  # noqa: E501
    ("hard-link", "opengym.py is a hard link (2 names for one file, possibly outside the submission): it was not read. Submit a copy of the file itself."),  # noqa: E501
    ("folder-link", "Expected one Python file (.py) or Jupyter notebook (.ipynb) with your functions, ideally named opengym.py; found no .py or .ipynb file. Submit exactly one such file. lab is a symbolic link (to {root}/source): links are never followed"),  # noqa: E501
]  # fmt: skip


@pytest.mark.parametrize(("kind", "message"), LINKED, ids=[case[0] for case in LINKED])
def test_an_upload_linking_to_the_secret_is_refused_and_the_secret_stays_private(
    tmp_path: Path, kind: str, message: str
) -> None:
    root = tmp_path / "autograder"
    _linked_upload(root, kind)
    secret_file = root / "source" / SECRET_FILE
    assert main(["gradescope-run", "--root", str(root), "--secret-file", str(secret_file)]) == 0
    text = (root / "results" / "results.json").read_text()
    data = json.loads(text)
    GradescopeResults.model_validate(data)
    assert NAME_LIKE_SECRET not in text, "not a byte of the secret in any result, visible or not"
    assert data["score"] == 0 and data["output"].startswith(message.format(root=root))
    assert data["extra_data"]["gymgrade"]["seed_source"] == "derived", "read before the upload, link or not"
    assert secret_file.stat().st_mode & 0o077 == 0, "unreadable to the sandbox's uid"


@pytest.mark.xdist_group("gradescope-bundle")  # one worker builds the `gradescope` bundle for all
def test_a_regrade_copies_an_uploads_links_as_links(gradescope: Path, tmp_path: Path) -> None:
    secret = tmp_path / "instructor_secret.txt"
    secret.write_text(NAME_LIKE_SECRET + "\n")
    upload = tmp_path / "upload"
    upload.mkdir()
    (upload / "opengym.py").symlink_to(secret)
    metadata_path = tmp_path / "meta.json"
    metadata_path.write_text(json.dumps(metadata(3002, "2026-11-26T09:05:00.000000-08:00", 9)))
    out = tmp_path / "results.json"
    arguments = ["--bundle", str(gradescope), "--metadata", str(metadata_path), "--out", str(out)]
    for submission in (upload, upload / "opengym.py"):
        assert main(["gradescope-seed", *arguments, "--submission", str(submission)]) == 0
        assert NAME_LIKE_SECRET not in out.read_text()
        assert json.loads(out.read_text())["output"].startswith("opengym.py is a symbolic link (to ")


def test_check_prints_valid_gradescope_results(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "opengym.ipynb"
    path.write_text("{not json")
    assert main(["check", str(path), "--format", "gradescope", "--only", "cartpole"]) == 1
    data = json.loads(capsys.readouterr().out)
    GradescopeResults.model_validate(data)
    assert data["score"] == 0 and [test["status"] for test in data["tests"]] == ["failed"]
    assert "opengym.ipynb is not a readable notebook" in data["output"]


def _controls(text: str) -> list[str]:
    """The control characters (but line breaks and tabs) in `text`."""
    return [
        character for character in text if unicodedata.category(character) == "Cc" and character not in "\n\t"
    ]


@pytest.mark.slow  # a grading through the sandbox
def test_control_characters_a_student_raised_and_printed_are_inert(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The hostile sample prints and raises ESC sequences and BELs: results.json (for Gradescope) and the text
    summary show each as U+FFFD, the report keeps them as the student wrote them."""
    sample = SUBMISSIONS / "hostile" / "control_characters.py"
    report_file = tmp_path / "report.json"
    main(["check", str(sample), "--only", "random_blackjack", "--output", str(report_file)])
    text = capsys.readouterr().out
    report = Report.model_validate_json(report_file.read_text(encoding="utf-8"))
    (problem,) = report.problems
    assert "\x1b[2J\x07" in problem.feedback and "\x07" in problem.output  # the report holds them as raised
    data = json.loads(results(report).to_json())
    outputs = [data["output"], *(test["output"] for test in data["tests"])]
    assert [_controls(output) for output in outputs] == [[] for _ in outputs]
    assert "ValueError: bad \ufffd[2J\ufffd value \ufffd[31mred\ufffd[0m" in data["tests"][0]["output"]
    assert "ring\ufffd the bell, \ufffd[31mred" in _printed(data)
    assert _controls(text) == [] and "ValueError: bad \ufffd[2J\ufffd value" in text
    for line in ("Traceback (most recent call last):", "Score: 0 / 1"):
        assert line in text.splitlines() or any(line in shown for shown in text.splitlines())


@pytest.mark.slow  # builds two bundles and runs one's autograder end to end
def test_each_bundle_draws_its_own_secret_and_keeps_it_private(tmp_path: Path) -> None:
    first, second = bundle(tmp_path / "a.zip", config=None), bundle(tmp_path / "b.zip", config=None)
    assert bundle_secret(first) != bundle_secret(second) and len(bundle_secret(first)) == 64
    with zipfile.ZipFile(first) as opened:
        assert opened.getinfo(SECRET_FILE).external_attr >> 16 & 0o077 == 0
        scripts = opened.read("run_autograder").decode() + opened.read("setup.sh").decode()
    assert bundle_secret(first) not in scripts and "--seed" not in scripts, "no seed on a command line"
    with pytest.raises(
        GradescopeError, match="expected an autograder zip built by gymgrade gradescope-bundle"
    ):
        bundle_secret(tmp_path / "nothing.zip")


@pytest.fixture(scope="module")
def gradescope(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An autograder zip of the cartpole problem alone (5 calls), with the tests' fixed secret."""
    directory = tmp_path_factory.mktemp("bundle")
    overrides: dict[str, dict[str, Any]] = {problem: {"enabled": False} for problem in PROBLEM_IDS}
    overrides["cartpole"] = {"enabled": True, "calls": 5}
    config = write_config(directory / "assignment.toml", overrides)
    return bundle(directory / "autograder.zip", config=config, secret=SECRET)


def _upload(archive: Path, root: Path, submission: Path, meta: dict[str, object]) -> dict[str, Any]:
    """Run the bundle's run_autograder as Gradescope does: a fresh root, the upload, its metadata."""
    with zipfile.ZipFile(archive) as opened:
        opened.extractall(root / "source")
    (root / "submission").mkdir()
    (root / "submission" / "opengym.py").write_bytes(submission.read_bytes())
    (root / METADATA_FILE).write_text(json.dumps(meta))
    os.chmod(root / "source" / "run_autograder", 0o755)
    environment = {
        **os.environ,
        "GYMGRADE_AUTOGRADER_ROOT": str(root),
        "GYMGRADE_COMMAND": f"{sys.executable} -m grader.cli",
        "PYTHONPATH": str(ROOT),
    }
    subprocess.run([str(root / "source" / "run_autograder")], env=environment, check=True, timeout=600)
    assert (root / "source" / SECRET_FILE).stat().st_mode & 0o077 == 0, "student code runs as another uid"
    assert (root / METADATA_FILE).stat().st_mode & 0o077 == 0, "it embeds earlier uploads' results"
    data: dict[str, Any] = json.loads((root / "results" / "results.json").read_text())
    GradescopeResults.model_validate(data)
    return data


def _printed(data: dict[str, Any]) -> str:
    (printed,) = [
        test["output"] for test in data["tests"] if test["name"].endswith("printed (instructor only)")
    ]
    return printed


def _cartpole(data: dict[str, Any]) -> dict[str, Any]:
    return next(test for test in data["tests"] if test["name"] == "Problem 3: CartPole")


def _tapes_module() -> Any:
    spec = importlib.util.spec_from_file_location("memorised_tapes", ROOT / "scripts" / "memorised_tapes.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.xdist_group("gradescope-bundle")  # one worker builds the `gradescope` bundle for all
@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:.*CartPole-v0 is out of date:DeprecationWarning")
def test_two_uploads_get_different_starts_and_a_recorded_one_regrades_identically(
    gradescope: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    printer = SUBMISSIONS / "hostile" / "start_printer.py"
    first_meta = metadata(1001, "2026-11-25T10:00:00.000000-08:00", 5)
    first = _upload(gradescope, tmp_path / "first", printer, first_meta)
    second = _upload(
        gradescope, tmp_path / "second", printer, metadata(1002, "2026-11-25T10:05:00.000000-08:00", 5)
    )

    tapes = _tapes_module()
    first_starts, second_starts = (
        tapes.printed_starts(_printed(first)),
        tapes.printed_starts(_printed(second)),
    )
    assert len(first_starts) == len(second_starts) == 5
    assert not set(map(tuple, first_starts)) & set(map(tuple, second_starts)), "a start came back"
    assert _cartpole(first)["status"] == _cartpole(second)["status"] == "passed"
    for data in (first, second):
        seen = json.dumps(student_sees(data))
        assert "start [" not in seen and str(data["extra_data"]["gymgrade"]["seed"]) not in seen
        assert SECRET not in json.dumps(data), "the secret is in no results, not even the instructor's"

    metadata_path = tmp_path / "first.json"
    metadata_path.write_text(json.dumps(first_meta))
    identity = read_metadata(metadata_path).identity()
    expected_seed = upload_seed(SECRET, identity)
    assert first["extra_data"]["gymgrade"] == {
        "seed": expected_seed, "seed_source": "derived", "identity": list(identity)
    }  # fmt: skip

    # The instructor reproduces the recorded upload from the zip and its metadata alone.
    regraded = tmp_path / "regraded.json"
    arguments = ["gradescope-seed", "--bundle", str(gradescope), "--metadata", str(metadata_path)]
    assert main([*arguments, "--submission", str(printer), "--out", str(regraded)]) == 0
    assert f"Grading seed {expected_seed} (upload gradescope, 1001," in capsys.readouterr().out
    again = json.loads(regraded.read_text())
    first.pop("execution_time"), again.pop("execution_time")
    assert again == first

    # The attack of issue 22: tapes for the starts the first upload printed, uploaded again.
    attack = tmp_path / "start_keyed_tapes.py"
    attack.write_text(tapes.keyed_source(first_starts))
    replayed = _upload(
        gradescope, tmp_path / "third", attack, metadata(1003, "2026-11-25T10:10:00.000000-08:00", 5)
    )
    assert _cartpole(replayed)["status"] == "failed", _cartpole(replayed)["output"]
    # Where the seed repeats (one seed per bundle, as before), the same tapes get full marks.
    assert main([*arguments, "--submission", str(attack), "--out", str(tmp_path / "same-seed.json")]) == 0
    assert _cartpole(json.loads((tmp_path / "same-seed.json").read_text()))["status"] == "passed"


@pytest.mark.xdist_group("gradescope-bundle")  # one worker builds the `gradescope` bundle for all
@pytest.mark.slow
def test_student_code_that_opens_the_secret_by_its_path_reads_nothing(
    gradescope: Path, tmp_path: Path
) -> None:
    root = tmp_path / "root"
    reader = tmp_path / "opengym.py"
    reader.write_text(
        "from pathlib import Path\n"
        "try:\n"
        f"    FOUND = 'read: ' + Path({str(root / 'source' / SECRET_FILE)!r}).read_text()\n"
        "except OSError as error:\n"
        "    FOUND = f'refused: {type(error).__name__}'\n\n\n"
        "def cartpole():\n"
        "    raise ValueError(FOUND)\n"
    )
    data = _upload(gradescope, root, reader, metadata(3003, "2026-11-26T09:10:00.000000-08:00", 9))
    assert SECRET not in json.dumps(data)
    assert "ValueError: refused: " in _cartpole(data)["output"], _cartpole(data)["output"]


@pytest.mark.slow
def test_a_current_edition_upload_is_graded_by_its_editions_bundle(tmp_path: Path) -> None:
    rl1 = EDITIONS["rl1"]
    overrides: dict[str, dict[str, Any]] = {problem: {"enabled": False} for problem in rl1.registry.ids}
    overrides["epsilon_decay"] = {"enabled": True}
    config = write_config(tmp_path / "assignment.toml", overrides, base=rl1.default_config)
    archive = bundle(tmp_path / "autograder.zip", config=config, secret=SECRET)
    meta = metadata(2001, "2026-11-25T11:00:00.000000-08:00", 7)
    data = _upload(archive, tmp_path / "root", rl1.reference, meta)
    graded = [test for test in data["tests"] if test["name"] == "Problem 5: epsilon_decay"]
    assert [(test["status"], test["score"]) for test in graded] == [("passed", 1.0)], data["tests"]
    assert data["score"] == 1.0
    assert "Edition: rl1 (Reinforcement Learning 1: Gymnasium)." in data["output"]
