"""`gymgrade grade`: a class download graded into its gradebooks, its class page and its similarity check.

The command line (`grader.cli`) parses the options; this module does the class's work: it recognises the
download, chooses each student's graded file, refuses output names that would overwrite a student's report,
grades the files not yet graded in --out (resuming an interrupted batch), and writes the gradebooks.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from collections.abc import Sequence
from importlib.metadata import entry_points
from pathlib import Path
from typing import TYPE_CHECKING

from grader.errors import EXIT_ERROR, EXIT_INTERRUPTED, BatchInterrupted, ExecutorUnavailable, GraderError
from grader.render.progress import ProgressBar
from grader.report import ProblemResult
from grader.sandbox import IsolationPolicy
from grader.seeds import held_out_seed

if TYPE_CHECKING:
    from grader.classroom.kept import InstructorData
    from grader.classroom.model import ClassDownload, Submission
    from grader.classroom.output import ClassGradebook
    from grader.classroom.roster import Roster
    from grader.grading.batch import BatchExecutor
    from grader.grading.plan import GradingPlan

EXECUTOR_GROUP = "gymgrade.executors"
"""Entry points ``factory(policy) -> BatchExecutor | None`` that `gymgrade grade` asks, in order, for an
executor; one that is not configured (e.g. no GYMGRADE_BROKER_URL) returns None, and the batch is local."""


def grade_class(args: argparse.Namespace) -> int:
    """`gymgrade grade`: recognise the class download, grade each student's file not yet graded in --out
    (reports named by identity), keep each report and the gradebooks as they are done."""
    from grader.classroom import GradedFileRule, read_all, submissions_of_all
    from grader.classroom.errors import GradebookError
    from grader.classroom.gradebooks import Assignment
    from grader.classroom.kept import chosen_submissions
    from grader.classroom.output import ClassGradebook
    from grader.classroom.roster import read_roster
    from grader.grading.plan import GradingPlan
    from grader.lab.labs import lab_of

    roster = read_roster(args.roster) if args.roster is not None else None
    if "canvas" in args.gradebook and not args.assignment_id:
        raise GradebookError(
            "--gradebook canvas needs --assignment-id ID (the number in the assignment's Canvas URL .../assignments/ID), so Canvas puts the scores in that assignment's column"  # noqa: E501
        )
    with tempfile.TemporaryDirectory(prefix="gymgrade-class-") as scratch:
        # Every enabled problem, not just --only's: the graded file must not change with --only.
        functions = GradingPlan.load(args.config, None).problems
        # Read once, within one budget for every target; files are grouped again without reading anything.
        reads = read_all(args.targets, layout=args.layout, sections=args.sections, scratch=Path(scratch))
        download = submissions_of_all(reads, rule=GradedFileRule(functions=functions), due=args.due)
        if getattr(args, "detect_editions", False):
            asked = _detect_class_edition(args, download)
            if asked is None:
                return EXIT_ERROR
            if asked != functions:  # the class's edition asks other functions: choose each file by them
                download = submissions_of_all(reads, rule=GradedFileRule(functions=asked), due=args.due)
        plan = GradingPlan.load(args.config, args.only)
        title = args.assignment_title or lab_of(plan.assignment.lab).assignment_title
        assignment = Assignment(title=title, lms_id=args.assignment_id)
        print(class_summary(download), file=sys.stderr, flush=True)
        graded = [submission for submission in download.submissions if submission.graded_file is not None]
        if not download.submissions and roster is None:
            print("gymgrade grade: no submissions found in the given targets", file=sys.stderr)
            return EXIT_ERROR
        identities = {
            submission.graded_file.path: submission.identity
            for submission in graded
            if submission.graded_file
        }
        if args.html is not None:
            clash = class_page_clash(args.html, list(identities.values()), args.out)
            if clash is not None:
                print(f"gymgrade grade: {clash}", file=sys.stderr)
                return EXIT_ERROR
        if args.reference and not args.similarity:
            print(
                "gymgrade grade: --reference is used by the similarity check; add --similarity (or leave out --reference)",  # noqa: E501
                file=sys.stderr,
            )
            return EXIT_ERROR
        if args.similarity:
            clash = similarity_clash(list(identities.values()), args.out, args.html)
            if clash is not None:
                print(f"gymgrade grade: {clash}", file=sys.stderr)
                return EXIT_ERROR
        instructor = _instructor_data(args, download, roster, plan)
        regrade = None
        if args.only_students is not None:
            chosen = chosen_submissions(download, args.only_students)
            regrade = {path for path, identity in identities.items() if identity in chosen}
        gradebook = ClassGradebook(
            download,
            identities,
            plan.problems,
            roster,
            args.gradebook,
            assignment,
            decisions=instructor.decisions,
        )
        code = _grade_class(
            args, list(identities), identities, gradebook, regrade, instructor, file_names_of(graded)
        )
        if args.similarity and code != EXIT_INTERRUPTED:
            return _similarity_beside_grading(args, download) or code
        return code


def file_names_of(submissions: Sequence[Submission]) -> dict[Path, str]:
    """Each graded file's own name as the download gives it (``graded_file.relative``'s last part,
    neutralised and bounded by `grader.render.neutral.file_name`), for what a person reads of its grading.

    A zip's entries are read into numbered files (``6.py``), so that no name a student or an LMS chose ever
    reaches the file system; this name is only shown, never used as a path. A folder's files keep their own
    names, so for them it is their ``path.name``."""
    from grader.render.neutral import file_name

    return {
        submission.graded_file.path: file_name(submission.graded_file.relative)
        for submission in submissions
        if submission.graded_file is not None
    }


def _instructor_data(
    args: argparse.Namespace, download: ClassDownload, roster: Roster | None, plan: GradingPlan
) -> InstructorData:
    """The instructor's overrides, late policy and given times for this class (kept in --out from earlier
    runs unless given again), each line about them printed."""
    from grader.classroom.gradebooks import class_rows
    from grader.classroom.kept import load_instructor_data
    from grader.render.neutral import terminal_line

    students = sorted({row.member.identity for row in class_rows(download, {}, roster)})
    data = load_instructor_data(
        out_dir=args.out,
        config=args.config,
        overrides=args.overrides,
        submitted_at=args.submitted_at,
        students=students,
        maxima=plan.points,
    )
    for line in data.lines:
        print(terminal_line(line), file=sys.stderr, flush=True)
    return data


def _detect_class_edition(args: argparse.Namespace, download: ClassDownload) -> tuple[str, ...] | None:
    """Detect each submission's edition and grade the class as the edition every file showing one asks the
    problems of (into ``args.config``), print which and why; return the functions of its enabled problems.
    None (after saying which editions were found and whose files are behind each) when the files disagree:
    the instructor names the assignment's edition, a majority of files never does."""
    from grader.grading.plan import GradingPlan
    from grader.lab.editions.per_submission import class_editions
    from grader.render.neutral import terminal_line

    files = {
        submission.identity: submission.graded_file.path
        for submission in download.submissions
        if submission.graded_file is not None
    }
    shown = file_names_of(download.submissions)
    editions = class_editions(files, {identity: shown[path] for identity, path in files.items()})
    if editions.disagreement is not None:
        for line in editions.lines()[1:]:  # each file's edition and why
            print(terminal_line(line), file=sys.stderr, flush=True)
        print(terminal_line(f"gymgrade grade: {editions.disagreement}"), file=sys.stderr, flush=True)
        return None
    print(editions.choice.lab_line, file=sys.stderr, flush=True)
    for line in editions.lines():
        print(terminal_line(line), file=sys.stderr, flush=True)
    args.config = editions.choice.config
    return GradingPlan.load(args.config, None).problems


def similarity_clash(identities: Sequence[str], out_dir: Path, page: Path | None) -> str | None:
    """Why `gymgrade grade --similarity` would overwrite a student's report or the --html class page (or its
    JSON summary) with one of its own files, or None."""
    from grader.classroom.similarity.command import CSV_FILE, HTML_FILE, JSON_FILE
    from grader.grading.batch import identity_stem

    if page is not None:
        own = {(out_dir / name).resolve() for name in (CSV_FILE, HTML_FILE, JSON_FILE)}
        if {page.resolve(), page.with_suffix(".json").resolve()} & own:
            return (
                f"--similarity writes {HTML_FILE} and {JSON_FILE} into --out, and --html {page} (or its JSON summary) is one of them; "  # noqa: E501
                "name the class page e.g. class.html"
            )
    stem = JSON_FILE.removesuffix(".json")
    clashing = [identity for identity in identities if identity_stem(identity) == stem]
    if not clashing:
        return None
    return (
        f"--similarity writes {JSON_FILE} into --out, but student {clashing[0]!r}'s report has that name; "
        "leave out --similarity and run `gymgrade similarity` with another --out after grading"
    )


def _similarity_beside_grading(args: argparse.Namespace, download: ClassDownload) -> int:
    """The similarity check of a graded batch, written into --out with the batch's reports as behaviour
    evidence. It reads only the download and the reports: grades.csv and the reports are left as they are.

    Returns:
        0, or EXIT_ERROR when the check could not run (the grades are written either way).
    """
    from grader.classroom.similarity.cache import IndexCache, default_cache_dir
    from grader.classroom.similarity.command import summarise, write_similarity
    from grader.classroom.similarity.sources import sources_of

    try:
        report = write_similarity(
            sources_of(download),
            args.out,
            args.reference,
            cache=IndexCache(default_cache_dir()),
            reports=args.out,
        )
    except (GraderError, ValueError, OSError) as error:
        print(
            f"gymgrade grade: the similarity check could not run ({error}); the grades in {args.out} are written and unaffected; "  # noqa: E501
            "run `gymgrade similarity` on the download to retry it",
            file=sys.stderr,
        )
        return EXIT_ERROR
    summarise(report, args.out, sys.stderr)
    return 0


def class_summary(download: ClassDownload) -> str:
    """What was found: the layout, which file is graded for whom and why, what was refused or unattributed."""
    from grader.classroom import LAYOUTS
    from grader.render.neutral import terminal_line as shown  # every name here is the student's choice

    title = LAYOUTS[download.layout].title if download.layout in LAYOUTS else download.layout
    lines = [f"Found {len(download.submissions)} submissions ({title}):"]
    for submission in download.submissions:
        graded = submission.graded_file.relative if submission.graded_file else "nothing graded"
        late = " [late]" if submission.late else ""
        lines.append(f"  {shown(submission.display_name)}{late}: {shown(graded)} ({shown(submission.why)})")
    for skipped in download.refused[:MAX_SKIPPED_SHOWN]:
        lines.append(f"  refused {shown(skipped.where)}: {shown(skipped.reason)}")
    if len(download.refused) > MAX_SKIPPED_SHOWN:
        lines.append(f"  ... and {len(download.refused) - MAX_SKIPPED_SHOWN:,} more refused")
    for skipped in download.unattributed[:MAX_SKIPPED_SHOWN]:
        lines.append(f"  not attributed {shown(skipped.where)}: {shown(skipped.reason)}")
    if len(download.unattributed) > MAX_SKIPPED_SHOWN:
        lines.append(f"  ... and {len(download.unattributed) - MAX_SKIPPED_SHOWN:,} more not attributed")
    return "\n".join(lines)


MAX_SKIPPED_SHOWN = 200
"""Refused (and unattributed) files the summary names; the rest are counted (a zip of 80,000 links is one
student's, and a reason in their row)."""


def _grade_class(
    args: argparse.Namespace,
    paths: list[Path],
    identities: dict[Path, str],
    gradebook: ClassGradebook,
    regrade: set[Path] | None = None,
    instructor: InstructorData | None = None,
    file_names: dict[Path, str] | None = None,
) -> int:
    from grader.classroom.kept import regrade_refusal
    from grader.grading.batch import BatchOutcome, grade_many
    from grader.grading.plan import GradingPlan
    from grader.render.neutral import IDENTITY_SHOWN_CHARS, display_identity

    policy = IsolationPolicy.ALLOW_FALLBACK if args.allow_weak_isolation else IsolationPolicy.REQUIRE_FULL
    executor = find_executor(policy)
    bar = ProgressBar(total=0)

    def planned(outcome: BatchOutcome) -> None:
        bar.total = max(len(outcome.graded) * len(problems_of(args)), 1)
        if outcome.reused:
            print(
                f"Resuming in {args.out}: {len(outcome.reused)} of {len(paths)} submissions are already graded there (same file, seed and configuration); "  # noqa: E501
                f"grading {len(outcome.graded)}.",
                file=sys.stderr,
            )
        if executor is not None:
            print(f"Grading on {executor}.", file=sys.stderr)

    shown = {path: display_identity(identity, IDENTITY_SHOWN_CHARS) for path, identity in identities.items()}

    def advance(path: Path, result: ProblemResult) -> None:
        bar.advance(f"{shown[path]}: {result.id} {result.status}")

    seed = choose_seed(args.seed, args.out)
    if regrade is not None:
        plan = GradingPlan.load(args.config, args.only)
        others = [identity for path, identity in identities.items() if path not in regrade]
        refusal = regrade_refusal(
            args.out, others, seed=seed, config_sha256=plan.config_sha256, problems=plan.problems
        )
        if refusal is not None:
            print(f"gymgrade grade: {refusal}", file=sys.stderr)
            return EXIT_ERROR
        print(
            f"Regrading {len(regrade)} submissions; every other report in {args.out} is kept as it is.",
            file=sys.stderr,
        )
    if instructor is not None:
        instructor.write_kept(args.out)
    try:
        outcome = grade_many(
            paths,
            args.out,
            seed=seed,
            workers=args.workers,
            only=args.only,
            policy=policy,
            config=args.config,
            on_result=advance,
            executor=executor,
            on_plan=planned,
            names=identities,
            gradebook=gradebook,
            regrade=regrade,
            file_names=file_names,
        )
    except BatchInterrupted as interruption:
        print(
            "\ngymgrade grade: interrupted. "
            f"{interruption.finished} of {interruption.total} submissions are graded in {args.out} (their reports and grades.csv are kept). "  # noqa: E501
            f"Run the same command again (same --out, --seed, --only and --config) to grade the other {interruption.total - interruption.finished}; "  # noqa: E501
            "the finished ones are skipped.",
            file=sys.stderr,
        )
        return EXIT_INTERRUPTED
    if args.html is not None and gradebook.rows is not None:
        write_class_page(args.html, gradebook, args.out)
    errors = sum(1 for report in outcome.reports if report.grader_errors)
    written = ", ".join(["grades.csv", *(f"{name}.csv" for name in args.gradebook)])
    if "canvas" in args.gradebook and gradebook.rows is not None:
        from grader.classroom.gradebooks import canvas_user_id

        unmatched = [
            display_identity(row.member.identity, IDENTITY_SHOWN_CHARS)
            for row in gradebook.rows
            if not canvas_user_id(row)
        ]
        if unmatched:
            print(
                f"canvas.csv leaves out {len(unmatched)} students without a Canvas user id ({', '.join(unmatched[:5])}{', ...' if len(unmatched) > 5 else ''}): "  # noqa: E501
                "pass --roster with a Canvas gradebook export (its ID column) to match them.",
                file=sys.stderr,
            )
    print(
        f"Graded {len(outcome.graded)} submissions"
        + (f" (reused {len(outcome.reused)} earlier reports)" if outcome.reused else "")
        + f" into {args.out} ({written}) with seed {seed}"
        + (f"; {errors} with grader errors (run again to retry them)" if errors else ""),
        file=sys.stderr,
    )
    return EXIT_ERROR if errors else 0


def class_page_clash(page: Path, identities: Sequence[str], out_dir: Path) -> str | None:
    """Why `gymgrade grade --html` would overwrite one of the batch's files (a student's report), or None."""
    from grader.classroom.report.from_batch import page_clash_of_reports
    from grader.grading.batch import identity_stem
    from grader.render.neutral import IDENTITY_SHOWN_CHARS, display_identity

    reports = {
        out_dir / f"{identity_stem(identity)}.json": "student "
        + display_identity(identity, IDENTITY_SHOWN_CHARS)
        for identity in identities
    }
    return page_clash_of_reports(page, reports, out_dir)


def write_class_page(page: Path, gradebook: ClassGradebook, out_dir: Path) -> None:
    """`gymgrade grade --html`: the class report of the batch, and its JSON summary beside it."""
    from grader.classroom.report import write_class_report
    from grader.classroom.report.from_batch import entries_from_rows

    summary = write_class_report(page, entries_from_rows(gradebook.rows or [], out_dir, page))
    print(f"Wrote the class report {page} and its summary {summary}.", file=sys.stderr)


def problems_of(args: argparse.Namespace) -> tuple[str, ...]:
    """The problems a `gymgrade grade` run covers."""
    from grader.grading.plan import GradingPlan

    return GradingPlan.load(args.config, args.only).problems


def find_executor(policy: IsolationPolicy) -> BatchExecutor | None:
    """The first configured executor of the ``gymgrade.executors`` entry points, or None (local).

    Raises:
        grader.errors.GraderError: An executor is configured but cannot be used (its message says why).
    """
    for entry_point in entry_points(group=EXECUTOR_GROUP):
        try:
            factory = entry_point.load()
        except Exception as error:
            raise ExecutorUnavailable(
                f"the batch executor {entry_point.name!r} could not be loaded ({type(error).__name__}: "
                f"{error}); reinstall the package providing it (pip install -e '.[distributed]')"
            ) from error
        executor: BatchExecutor | None = factory(policy)
        if executor is not None:
            return executor
    return None


def choose_seed(given: int | None, out_dir: Path) -> int:
    """The batch's grading seed, announced on stderr: ``--seed``, else the one an earlier (interrupted)
    batch recorded in ``out_dir``, so that re-running the same command resumes it, else a fresh held-out
    seed."""
    from grader.grading.batch import recorded_seed

    recorded = recorded_seed(out_dir) if given is None else None
    if given is not None:
        seed, origin = given, "given"
    elif recorded is not None:
        seed, origin = recorded, f"recorded in {out_dir / 'grades.csv'}; pass --seed for another"
    else:
        seed, origin = held_out_seed(), "held out, drawn at random"
    print(
        f"Grading seed {seed} ({origin}; regrade identically with --seed {seed})", file=sys.stderr, flush=True
    )
    return seed
