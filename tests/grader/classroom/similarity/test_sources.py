"""Bad input never stops the run: every file left out is listed with its reason."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from grader.classroom.similarity.errors import ClassDirectoryError
from grader.classroom.similarity.run import run_similarity
from grader.classroom.similarity.sources import read_source, submissions_from

CORPUS = Path(__file__).resolve().parents[4] / "submissions" / "similarity"
GOOD = (CORPUS / "class" / "h01_loops.py").read_text(encoding="utf-8")
COPY = (CORPUS / "class" / "c_renamed_from_h01.py").read_text(encoding="utf-8")

BAD_FILES: dict[str, tuple[bytes, str]] = {
    "unparseable.py": (b"def random_blackjack(n:\n    return 0\n", "is not valid Python (line 1)"),
    "huge.py": (b"x = 1\n" * 40_000, "is larger than 200,000 bytes"),
    "binary.py": (b"\x7fELF\x02\x01\x01\0\0\0" * 10, "is binary"),
    "latin1.py": ("# café\nx = 1\n".encode("latin-1"), "is not UTF-8 text"),
    "empty.py": (b"  \n\n", "is empty"),
    "deep.py": (b"x = " + b"[" * 5000 + b"]" * 5000 + b"\n", "is not valid Python"),
    "not_json.ipynb": (b"{ this is not json", "not valid JSON"),
    "no_cells.ipynb": (
        json.dumps({"nbformat": 4, "metadata": {}}).encode(),
        "is JSON but not a Jupyter notebook",
    ),
    "only_markdown.ipynb": (
        json.dumps({"nbformat": 4, "cells": [{"cell_type": "markdown", "source": "hi"}]}).encode(),
        "has no code cells",
    ),
    "notes.txt": (b"my answers are in the notebook", "not attributed to a student: a file outside every"),
}


@pytest.fixture
def class_dir(tmp_path: Path) -> Path:
    folder = tmp_path / "class"
    folder.mkdir()
    (folder / "ana.py").write_text(GOOD, encoding="utf-8")
    (folder / "ben.py").write_text(COPY, encoding="utf-8")
    for name, (data, _) in BAD_FILES.items():
        (folder / name).write_bytes(data)
    (folder / "empty_folder").mkdir()
    (folder / "fay").mkdir()
    (folder / "fay" / "README.md").write_text("my answers are in the notebook I forgot\n", encoding="utf-8")
    (folder / ".hidden.py").write_text("x = 1\n", encoding="utf-8")
    return folder


def test_every_bad_file_is_listed_with_its_reason_and_the_rest_is_still_compared(class_dir: Path) -> None:
    report = run_similarity(class_dir).report
    reasons = {entry.file: entry.reason for entry in report.unreadable}
    for name, (_, expected) in BAD_FILES.items():
        assert expected in reasons[name], (name, reasons.get(name))
    assert "is neither a .py nor an .ipynb file" in reasons["fay/README.md"]
    assert "empty_folder" not in reasons, "an empty folder is no submission, as for gymgrade grade"
    assert ".hidden.py" not in reasons
    assert report.students == ["ana", "ben"]
    assert [(pair.a, pair.b) for pair in report.pairs] == [("ana", "ben")]


def test_an_empty_class_gives_an_empty_report_that_says_so(tmp_path: Path) -> None:
    report = run_similarity(tmp_path).report
    assert (report.students, report.pairs, report.clusters) == ([], [], [])
    assert report.notes == ["no readable submission was found in the class folder: nothing was compared."]


def test_a_missing_class_folder_is_an_error_that_says_what_to_pass(tmp_path: Path) -> None:
    with pytest.raises(
        ClassDirectoryError, match=r"expected a class folder .* found nothing at .*missing; pass the folder"
    ):
        run_similarity(tmp_path / "missing")


def test_a_student_folder_holds_every_candidate_file_of_the_student_the_graded_one_first(
    tmp_path: Path,
) -> None:
    (tmp_path / "cara" / "lab").mkdir(parents=True)
    (tmp_path / "cara" / "lab" / "opengym.py").write_text("x = 1\n", encoding="utf-8")
    (tmp_path / "cara" / "helpers.ipynb").write_text("{}", encoding="utf-8")
    (tmp_path / "cara" / ".ipynb_checkpoints").mkdir()
    (tmp_path / "cara" / ".ipynb_checkpoints" / "helpers-checkpoint.ipynb").write_text("{}", encoding="utf-8")
    (tmp_path / "cara" / "test_opengym.py").write_text("def test_x():\n    pass\n", encoding="utf-8")
    (tmp_path / "dan.ipynb").write_text("{}", encoding="utf-8")
    sources = submissions_from(tmp_path)
    assert sources.layout == "plain"
    assert [
        (identity, [path.relative_to(tmp_path).as_posix() for path in paths])
        for identity, paths in sources.submissions
    ] == [
        ("cara", ["cara/lab/opengym.py", "cara/helpers.ipynb"]),
        ("dan", ["dan.ipynb"]),
    ]


def test_a_notebooks_magics_are_blanked_and_its_cells_joined(tmp_path: Path) -> None:
    path = tmp_path / "n.ipynb"
    cells = [
        {"cell_type": "code", "source": ["%matplotlib inline\n", "import gym"]},
        {"cell_type": "markdown", "source": "text"},
        {"cell_type": "code", "source": "!pip install gym\nx = 1"},
    ]
    path.write_text(json.dumps({"nbformat": 4, "cells": cells}), encoding="utf-8")
    source = read_source(path)
    assert getattr(source, "text", None) == "\nimport gym\n\n\nx = 1\n"


def test_a_multi_file_student_is_one_document_whose_lines_cite_each_file(tmp_path: Path) -> None:
    (tmp_path / "eve").mkdir()
    (tmp_path / "eve" / "a.py").write_text(GOOD, encoding="utf-8")
    (tmp_path / "eve" / "b.py").write_text("def helper(x):\n    return x\n", encoding="utf-8")
    (tmp_path / "fay.py").write_text(COPY, encoding="utf-8")
    outcome = run_similarity(tmp_path)
    pair = outcome.report.pairs[0]
    lines = outcome.lines_of("eve")
    assert lines[0] == "# ==== a.py ===="
    fragment = pair.fragments[0]
    eve_first = fragment.a_first if pair.a == "eve" else fragment.b_first
    fay_first = fragment.b_first if pair.a == "eve" else fragment.a_first
    assert (
        eve_first == fay_first + 1
    )  # the copy keeps h01's line numbers; eve's text starts with a header line
    assert lines[eve_first - 1] == GOOD.splitlines()[fay_first - 1]


@pytest.mark.slow
def test_indexing_in_a_process_pool_gives_the_report_of_indexing_in_process(tmp_path: Path) -> None:
    from grader.classroom.similarity.run import BATCH

    for number in range(BATCH + 6):
        body = (
            GOOD if number % 2 else GOOD.replace("wins", f"wins_{number}").replace("10000", str(number + 11))
        )
        (tmp_path / f"s{number:03d}.py").write_text(body, encoding="utf-8")
    assert run_similarity(tmp_path, workers=2).report == run_similarity(tmp_path, workers=1).report


def test_a_notebook_cell_that_is_not_python_is_left_out_alone(tmp_path: Path) -> None:
    good_cells = [{"cell_type": "code", "source": chunk} for chunk in GOOD.split("\n\n\n")]
    broken = {"cell_type": "code", "source": "def taxi(q_table:\n    return"}
    notebook = {"nbformat": 4, "cells": [*good_cells[:2], broken, *good_cells[2:]]}
    (tmp_path / "gil.ipynb").write_text(json.dumps(notebook), encoding="utf-8")
    (tmp_path / "hal.py").write_text(COPY, encoding="utf-8")
    report = run_similarity(tmp_path).report
    assert [(pair.a, pair.b) for pair in report.pairs] == [("gil", "hal")]
    assert report.notes == ["gil: gil.ipynb: cell 3 is not valid Python and was not compared."]


def test_a_symbolic_link_is_listed_and_never_followed(tmp_path: Path) -> None:
    (tmp_path / "ivy.py").symlink_to("/dev/zero")
    (tmp_path / "jon.py").write_text(GOOD, encoding="utf-8")
    report = run_similarity(tmp_path).report
    assert [(entry.identity, entry.file, entry.reason) for entry in report.unreadable] == [
        ("ivy", "ivy.py", "refused: a symbolic link (to /dev/zero): links are never followed.")
    ]


def test_thousands_of_refused_entries_are_listed_up_to_a_cap_and_counted(tmp_path: Path) -> None:
    """Hostile: one student's zip of 3,000 link entries is read in linear time and listed in 21 lines."""
    import zipfile

    from grader.classroom.similarity.sources import MAX_REFUSED_LISTED

    folder = tmp_path / "class"
    for name, text in (("ana", GOOD), ("ben", COPY)):
        (folder / name).mkdir(parents=True)
        (folder / name / "opengym.py").write_text(text, encoding="utf-8")
    with zipfile.ZipFile(folder / "ben" / "links.zip", "w") as bundle:
        for number in range(3_000):
            link = zipfile.ZipInfo(f"l{number}.py")
            link.external_attr = 0o120777 << 16
            bundle.writestr(link, "/etc/passwd")
        bundle.writestr("../outside.py", "x = 1\n")
    sources = submissions_from(folder, scratch=tmp_path / "scratch")
    bens = [skipped for skipped in sources.skipped if skipped.identity == "ben"]
    assert len(bens) == MAX_REFUSED_LISTED + 1
    assert bens[-1].file == "2,981 more refused files"
    assert sources.identities == ["ana", "ben"], "the refused entries make no student of their own"
    report = run_similarity(sources, workers=1).report
    assert [(pair.a, pair.b) for pair in report.pairs] == [("ana", "ben")]
