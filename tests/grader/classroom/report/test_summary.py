"""The class summary: score distribution, pass rates, diagnoses grouped by cause, late and missing."""

from __future__ import annotations

import hashlib
import json
import random

import pytest

from grader.classroom.report import ClassEntry, class_summary, diagnosis_key, diagnosis_text
from grader.classroom.report.summary import MAX_DIAGNOSES
from grader.render.neutral import HIDDEN, MAX_DIAGNOSIS_CHARS

from .support import OFF_BY_ONE, SHORT_POLE, STOOD_ON_N, all_passed, graded, report, result

SUMMARY_KEYS = [
    "format", "title", "lab", "edition", "students", "graded", "missing", "late", "overridden", "extended",
    "submission_errors", "scores", "problems", "diagnoses", "diagnoses_left_off", "entries",
]  # fmt: skip


def test_an_empty_class_has_every_key_and_nothing_in_them() -> None:
    summary = class_summary([])
    assert list(summary) == SUMMARY_KEYS
    assert summary["scores"] == {
        "count": 0, "max_score": 0.0, "mean": None, "median": None, "min": None, "max": None,
        "full_marks": 0, "bins": [],
    }  # fmt: skip
    assert (summary["problems"], summary["diagnoses"], summary["entries"]) == ([], [], [])
    assert (summary["lab"], summary["edition"]) == ("", ""), "nothing graded: no lab to name"
    json.dumps(summary, allow_nan=False)


@pytest.mark.parametrize(
    ("statuses", "expected"),
    [
        (["passed", "passed"], (2, 2, 1.0, {"passed": 2})),
        (["passed", "failed", "error", "timeout"],
         (4, 1, 0.25, {"error": 1, "failed": 1, "passed": 1, "timeout": 1})),
        (["passed", "skipped", "missing"], (2, 1, 0.5, {"missing": 1, "passed": 1, "skipped": 1})),
        (["skipped", "skipped"], (0, 0, None, {"skipped": 2})),
    ],
    ids=["all-pass", "one-of-four", "skipped-not-counted", "nobody-ran-it"],
)  # fmt: skip
def test_a_problems_pass_rate_counts_the_graded_submissions_that_ran_it(
    statuses: list[str], expected: tuple[int, int, float | None, dict[str, int]]
) -> None:
    entries = [graded(f"s{index}", result("taxi", status)) for index, status in enumerate(statuses)]  # type: ignore[arg-type]
    [taxi] = class_summary(entries)["problems"]
    assert (taxi["graded"], taxi["passed"], taxi["pass_rate"], taxi["statuses"]) == expected
    assert (taxi["id"], taxi["title"]) == ("taxi", "Problem 5")


def test_problems_keep_the_reports_order_and_submission_errors_and_missing_students_are_not_counted() -> None:
    entries = [
        graded("a", result("blackjack", "passed"), result("cartpole", "failed", "x")),
        graded("b", result("blackjack", "failed", "y"), result("cartpole", "failed", "x")),
        ClassEntry("c", report=report(result("blackjack", "error", "empty"), submission_error="empty"),
                   status="submission_error"),
        ClassEntry("d", status="missing"),
    ]  # fmt: skip
    problems = class_summary(entries)["problems"]
    assert [(row["id"], row["passed"], row["graded"]) for row in problems] == [
        ("blackjack", 1, 2),
        ("cartpole", 0, 2),
    ]


@pytest.mark.parametrize(
    ("scores", "max_score", "counts", "stats"),
    [
        ([0, 10, 5, 5], 10, [1, 0, 0, 0, 0, 2, 0, 0, 0, 1], (2.5 * 2, 5, 0, 10)),
        ([9.99, 1], 10, [0, 1, 0, 0, 0, 0, 0, 0, 0, 1], (5.495, 5.495, 1, 9.99)),
        ([3], 3, [0, 0, 0, 0, 0, 0, 0, 0, 0, 1], (3, 3, 3, 3)),
    ],
    ids=["full-and-zero-at-the-ends", "just-under-full", "one-student"],
)
def test_scores_fall_in_ten_bins_from_zero_to_the_maximum_the_top_one_closed(
    scores: list[float], max_score: float, counts: list[int], stats: tuple[float, ...]
) -> None:
    entries = []
    for index, score in enumerate(scores):
        entry = graded(f"s{index}", result("taxi", "passed", points=max_score))
        assert entry.report is not None
        entries.append(ClassEntry(entry.identity, report=entry.report.model_copy(update={"score": score})))
    distribution = class_summary(entries)["scores"]
    assert [row["count"] for row in distribution["bins"]] == counts
    assert distribution["bins"][0]["low"] == 0 and distribution["bins"][-1]["high"] == max_score
    assert (
        distribution["mean"],
        distribution["median"],
        distribution["min"],
        distribution["max"],
    ) == pytest.approx(stats)


def test_problems_come_in_the_reports_order_whoever_is_listed_first() -> None:
    entries = [
        graded("a", result("cartpole", "passed")),
        graded(
            "b",
            result("blackjack", "failed", "x"),
            result("cartpole", "failed", "y"),
            result("taxi", "passed"),
        ),
    ]
    assert [row["id"] for row in class_summary(entries)["problems"]] == ["blackjack", "cartpole", "taxi"]


def test_a_class_worth_nothing_puts_every_score_in_one_bin() -> None:
    entries = [graded("a", result("find_qvalues", "passed", points=0.0))]
    assert class_summary(entries)["scores"]["bins"] == [{"low": 0.0, "high": 0.0, "count": 1}]


def test_submission_errors_score_zero_in_the_distribution_and_missing_students_not_at_all() -> None:
    entries = [
        all_passed("a"),
        ClassEntry("b", report=report(result("taxi", "error", "not UTF-8"), submission_error="not UTF-8"),
                   status="submission_error"),
        ClassEntry("c", status="missing", name="Carol"),
    ]  # fmt: skip
    summary = class_summary(entries)
    assert (summary["students"], summary["graded"], summary["scores"]["count"]) == (3, 1, 2)
    assert summary["scores"]["full_marks"] == 1
    assert summary["missing"] == ["c"]
    assert [(row["identity"], row["note"]) for row in summary["submission_errors"]] == [("b", "not UTF-8")]


@pytest.mark.parametrize(
    ("feedback", "text"),
    [
        ("blackjack(14) returned 0.31", "blackjack(#) returned #"),
        ("wins 0.4170 of games (4080..4260 of 10000)", "wins # of games (#..# of #)"),
        ("mean -771.09 within 1e-06", "mean # within #"),
        ("CartPole-v0 and Taxi-v3 on gym 0.26 (v0.26)", "CartPole-v0 and Taxi-v3 on gym # (v0.26)"),
        ("resets 3, 5, 8, 13, 21, ... took no step", "resets # took no step"),
        ("resets 3 took no step", "resets # took no step"),
        ("line one\n\n  line two", "line one line two"),
        ("a \u202eright-to-left\u202c override", f"a {HIDDEN}right-to-left{HIDDEN} override"),
    ],
    ids=[
        "call-and-value",
        "band",
        "signs-and-exponents",
        "names-keep-their-digits",
        "a-list",
        "a-list-of-one",
        "whitespace",
        "bidi",
    ],
)
def test_a_diagnosis_is_the_feedback_with_its_numbers_replaced(feedback: str, text: str) -> None:
    assert diagnosis_text(feedback) == text


def test_a_diagnosis_does_not_depend_on_the_students_file_name() -> None:
    trace = 'car() raised ValueError: x Traceback: File "/submission/{}", line {}, in car'
    first = diagnosis_text(
        trace.format("smithjane_1234_5678_opengym.py", 2), "smithjane_1234_5678_opengym.py"
    )
    second = diagnosis_text(
        trace.format("doejohn_LATE_99_100_opengym-1.py", 7), "doejohn_LATE_99_100_opengym-1.py"
    )
    assert (
        first == second == 'car() raised ValueError: x Traceback: File "/submission/<file>", line #, in car'
    )


@pytest.mark.parametrize(
    ("feedback", "submission", "text"),
    [
        (
            'File "/submission/a.py", line 3: import data.py',
            "a.py",
            'File "/submission/<file>", line #: import data.py',
        ),
        ("a.py defines no car(); a.pyc", "a.py", "<file> defines no car(); a.pyc"),
        ("x (1).py is empty", "x (1).py", "<file> is empty"),
        ("opengym.py is empty", "", "opengym.py is empty"),
    ],
    ids=["a-path-not-another-name", "at-the-start-not-a-longer-name", "odd-characters", "no-name"],
)
def test_only_the_files_own_name_is_replaced(feedback: str, submission: str, text: str) -> None:
    assert diagnosis_text(feedback, submission) == text


def test_a_diagnosis_of_huge_feedback_is_bounded() -> None:
    text = diagnosis_text("x" * 10_000_000)
    assert len(text) == MAX_DIAGNOSIS_CHARS and text.endswith("…")


def test_the_diagnosis_key_names_problem_and_status_and_is_stable() -> None:
    digest = hashlib.sha256(b"check `<` versus `<=`").hexdigest()[:12]
    assert diagnosis_key("blackjack", "failed", "check `<` versus `<=`") == f"blackjack:failed:{digest}"
    assert diagnosis_key("blackjack", "failed", "a") != diagnosis_key("blackjack", "error", "a")
    assert diagnosis_key("blackjack", "failed", "a") != diagnosis_key("taxi", "failed", "a")


def _class() -> list[ClassEntry]:
    stood = [
        graded(f"u{index:03d}", result("blackjack", "failed", STOOD_ON_N.format(n=n, rate=rate, hands=hands)),
               result("cartpole", "passed"))
        for index, (n, rate, hands) in enumerate([(14, 0.31, 212), (17, 0.39, 30), (12, 0.4, 801)])
    ]  # fmt: skip
    off = [graded("u100", result("blackjack", "failed", OFF_BY_ONE.format(n=14, m=15, rate=0.41, hands=90)),
                  result("cartpole", "failed", SHORT_POLE.format(mean=120.5, episodes=100)))]  # fmt: skip
    short = result("cartpole", "failed", SHORT_POLE.format(mean=80, episodes=100))
    pole = [graded("u200", result("blackjack", "passed"), short, late=True)]
    return [*stood, *off, *pole, all_passed("u300"), ClassEntry("u400", status="missing")]


def test_diagnoses_group_students_by_cause_most_common_first() -> None:
    diagnoses = class_summary(_class())["diagnoses"]
    assert [(row["problem"], row["count"], row["identities"]) for row in diagnoses] == [
        ("blackjack", 3, ["u000", "u001", "u002"]),
        ("cartpole", 2, ["u100", "u200"]),
        ("blackjack", 1, ["u100"]),
    ]
    first = diagnoses[0]
    assert first["status"] == "failed" and first["title"] == "Problem 2"
    assert first["text"].endswith(
        "Your games stood on a sum of exactly # in # hands, so they follow 'draw while the sum is < #': "
        "check `<` versus `<=`."
    )
    assert first["key"] == diagnosis_key("blackjack", "failed", first["text"])


def test_passed_and_skipped_results_are_no_diagnosis_and_each_student_counts_once() -> None:
    twice = graded("a", result("blackjack", "failed", "same 1"), result("cartpole", "skipped", "not run"))
    assert twice.report is not None
    again = twice.report.model_copy(
        update={"problems": [*twice.report.problems, result("blackjack", "failed", "same 2")]}
    )
    diagnoses = class_summary([ClassEntry("a", report=again), all_passed("b")])["diagnoses"]
    assert [(row["problem"], row["count"], row["identities"]) for row in diagnoses] == [
        ("blackjack", 1, ["a"])
    ]


def test_late_and_missing_students_are_listed_by_identity() -> None:
    summary = class_summary(_class())
    assert (summary["late"], summary["missing"]) == (["u200"], ["u400"])
    assert [row["identity"] for row in summary["entries"]] == [
        "u000",
        "u001",
        "u002",
        "u100",
        "u200",
        "u300",
        "u400",
    ]
    assert summary["entries"][-1] == {
        "identity": "u400", "name": None, "status": "missing", "score": None, "max_score": None,
        "late": False, "note": "", "report_href": None, "machine_score": None, "late_penalty": None,
        "extended_to": None, "overrides": [],
    }  # fmt: skip


def test_the_summary_does_not_depend_on_the_order_of_the_entries() -> None:
    entries = _class()
    shuffled = entries[:]
    random.Random(20).shuffle(shuffled)
    assert shuffled != entries
    assert json.dumps(class_summary(shuffled)) == json.dumps(class_summary(entries))


def test_identities_keep_leading_zeros_and_rare_diagnoses_beyond_the_limit_are_counted() -> None:
    entries = [
        graded(f"{index:05d}", result("taxi", "failed", f"cause {'x' * index}"))
        for index in range(MAX_DIAGNOSES + 3)
    ]
    summary = class_summary(entries)
    assert summary["entries"][0]["identity"] == "00000"
    assert (len(summary["diagnoses"]), summary["diagnoses_left_off"]) == (MAX_DIAGNOSES, 3)


def test_the_summary_names_the_lab_and_edition_of_its_reports() -> None:
    first = class_summary([all_passed("alice"), graded("bob", result("blackjack", "failed"))])
    assert (first["lab"], first["edition"]) == (
        "opengym (OpenGym AI / Reinforcement Learning 1)",
        "classic (OpenGym AI (classic gym))",
    )
    second = report(result("blackjack", "passed")).model_copy(update={"lab": "rl2", "edition": "v2024"})
    mixed = class_summary([all_passed("alice"), ClassEntry(identity="carol", report=second)])
    assert mixed["lab"] == (
        "opengym (OpenGym AI / Reinforcement Learning 1), "
        "rl2 (Policy Function Iteration / Reinforcement Learning 2)"
    ), "kept reports of another lab are not hidden"
    # Hostile: a kept report naming a lab no gymgrade has is shown as one bounded, inert line.
    forged = report(result("blackjack", "passed")).model_copy(update={"lab": "x\u202e\n" * 200})
    shown = class_summary([ClassEntry(identity="mallory", report=forged)])["lab"]
    assert "\n" not in shown and "\u202e" not in shown and len(shown) <= 120
