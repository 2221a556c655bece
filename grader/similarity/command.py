"""`gymgrade similarity CLASS_DIR [--reference DIR ...] --out OUT`: parse, compare, write the outputs."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

CSV_FILE = "similarity.csv"
HTML_FILE = "similarity.html"
JSON_FILE = "similarity.json"


def add_similarity_command(subparsers: Any) -> None:
    """Register the subcommand on `gymgrade`'s subparsers."""
    parser = subparsers.add_parser(
        "similarity",
        help="rank pairs of submissions whose code is alike beyond the template (changes no grade)",
    )
    parser.add_argument(
        "class_dir", type=Path, metavar="CLASS_DIR", help="one folder or one file per student"
    )
    parser.add_argument(
        "--reference",
        type=Path,
        action="append",
        default=[],
        metavar="DIR",
        help="a folder of known solutions (earlier years, public repositories); may be repeated",
    )
    parser.add_argument(
        "--out", type=Path, required=True, metavar="DIR", help="where similarity.csv/.html go"
    )
    parser.add_argument(
        "--template",
        type=Path,
        action="append",
        default=None,
        metavar="FILE",
        help="the file handed out to students (default: every edition's template); may be repeated",
    )
    parser.add_argument(
        "--reports",
        type=Path,
        default=None,
        metavar="DIR",
        help="gymgrade grading reports (<student>.json): identical wrong results count as evidence",
    )
    parser.add_argument(
        "--cache",
        type=Path,
        default=None,
        metavar="DIR",
        help="where reference indexes are kept (default: ~/.cache/gymgrade/similarity)",
    )
    parser.add_argument("--no-cache", action="store_true", help="index the references again and keep nothing")
    parser.set_defaults(handler=run_similarity_command)


def run_similarity_command(args: argparse.Namespace) -> int:
    """Run the comparison and write ``similarity.csv``, ``similarity.html`` and ``similarity.json``."""
    from grader.similarity.behaviour import WrongResults, load_wrong_results
    from grader.similarity.cache import IndexCache, default_cache_dir
    from grader.similarity.csv_output import render_csv
    from grader.similarity.html_output import render_html
    from grader.similarity.run import run_similarity
    from grader.similarity.sources import submissions_from
    from grader.similarity.template import BUNDLED, load_template

    template = load_template(tuple(args.template) if args.template else BUNDLED)
    cache = None if args.no_cache else IndexCache(args.cache or default_cache_dir())
    behaviour: dict[str, WrongResults] | None = None
    notes: list[str] = []
    if args.reports is not None:
        identities = sorted({identity for identity, _ in submissions_from(args.class_dir)})
        behaviour, notes = load_wrong_results(args.reports, identities)
    outcome = run_similarity(
        args.class_dir, args.reference, template=template, cache=cache, behaviour=behaviour, notes=notes
    )
    report = outcome.report
    args.out.mkdir(parents=True, exist_ok=True)
    with (args.out / CSV_FILE).open("w", encoding="utf-8", newline="") as stream:
        stream.write(render_csv(report))
    (args.out / HTML_FILE).write_text(render_html(report, outcome.lines_of), encoding="utf-8")
    (args.out / JSON_FILE).write_text(report.model_dump_json(indent=2) + "\n", encoding="utf-8")
    print(
        f"Compared {len(report.students)} students"
        + (
            f" with each other and with {report.references} reference files"
            if report.references
            else " with each other"
        )
        + f": {len(report.pairs)} pairs flagged for reading, in {len(report.clusters)} groups"
        + (f"; {len(report.unreadable)} files left out (listed in {HTML_FILE})" if report.unreadable else "")
        + ".",
    )
    for note in report.notes:
        print(f"  {note}")
    print(f"Wrote {args.out / CSV_FILE}, {args.out / HTML_FILE} and {args.out / JSON_FILE}.", file=sys.stdout)
    return 0
