"""Similarity check (issue 21): detection per disguise, false positives, copydetect beside it, and scale.

Part 1 (detection). The ten honest solutions of submissions/similarity/class (h01..h10, written
independently, each given the template's untouched find_qvalues as students hand it in) are disguised
by one transformation at a time, applied by this script: renamed identifiers, comments and docstrings
changed, functions reordered, dead code padded, a notebook instead of a .py, and all five at once. Each
disguise makes one class of 20 (ten originals, ten disguised copies). Detection rate: share of the ten
(original, copy) pairs flagged. False-positive rate: share of the other 180 pairs of each class (two
independent solutions, or a copy and another student's original) flagged. copydetect (MIT, the anchor
the issue names; pip install copydetect, not a project dependency) runs on the same files with the
lab's templates as its boilerplate and flags a pair at its default display threshold (0.33).

Part 2 (scale). 300 students and 1,000 reference files generated at random (about 120 lines each, five
functions of random loops, branches and env calls; 10 students copy a reference, renamed): a cold run
(every reference indexed and cached), a warm run (references from the cache), the peak memory.

Part 3 (refused entries, issue 33; only with --refused-links N ...): two students, one of whom hands in a
zip of N symbolic-link entries; the seconds to read the class as the similarity check does
(`submissions_from`, discovery included) and how many lines list the refusals.

    python bench/similarity.py [--students 300] [--references 1000] [--skip-copydetect] [--scale-only]
    python bench/similarity.py --refused-links 20000 80000
"""

from __future__ import annotations

import argparse
import ast
import io
import json
import random
import resource
import sys
import tempfile
import time
import tokenize
from itertools import combinations
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from grader.classroom.similarity.cache import IndexCache  # noqa: E402
from grader.classroom.similarity.run import run_similarity  # noqa: E402
from grader.classroom.similarity.template import BUNDLED  # noqa: E402

CORPUS = ROOT / "submissions" / "similarity" / "class"
BASES = sorted(CORPUS.glob("h[0-9][0-9]_*.py"))
TEMPLATE = (ROOT / "submissions" / "template.py").read_text(encoding="utf-8")
FIND_QVALUES = TEMPLATE[TEMPLATE.index("def find_qvalues") : TEMPLATE.index("# Problem 1")]
WORDS = [
    "alpha",
    "beta",
    "gamma",
    "delta",
    "kappa",
    "omega",
    "river",
    "stone",
    "cloud",
    "ember",
    "frost",
    "maple",
    "cedar",
    "pixel",
    "orbit",
    "comet",
    "lumen",
]
BUILTINS = set(dir(__builtins__)) | {
    "np",
    "gym",
    "random",
    "plt",
    "Counter",
    "partial",
    "count",
    "clear_output",
    "self",
}


def renamed(source: str, rng: random.Random) -> str:
    tree = ast.parse(source)
    bound = {
        node.id for node in ast.walk(tree) if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store)
    }
    bound |= {node.arg for node in ast.walk(tree) if isinstance(node, ast.arg)}
    bound |= {node.name for node in ast.walk(tree) if isinstance(node, (ast.FunctionDef, ast.ClassDef))}
    lab = {
        "random_blackjack",
        "blackjack",
        "cartpole",
        "car",
        "taxi",
        "find_qvalues",
        "epsilon_decay",
        "sarsa0",
        "q_table",
        "q_table_decay",
        "n",
        "N",
        "env",
        "alpha",
        "gamma",
        "epsilon",
        "render",
        "decay",
        "episode",
        "epsilon_start",
        "epsilon_end",
    }
    mapping = {
        name: f"{rng.choice(WORDS)}_{index}" for index, name in enumerate(sorted(bound - lab - BUILTINS))
    }
    methods = {
        item.name
        for node in ast.walk(tree)
        if isinstance(node, ast.ClassDef)
        for item in node.body
        if isinstance(item, ast.FunctionDef)
    }
    tokens = []
    previous = ""
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        # like an editor's rename: env.step stays, a method of the student's own class is renamed everywhere
        if token.type == tokenize.NAME and (previous != "." or token.string in methods):
            token = token._replace(string=mapping.get(token.string, token.string))
        previous = token.string
        tokens.append(token)
    return tokenize.untokenize(tokens)


def comments_changed(source: str, rng: random.Random) -> str:
    tree = ast.parse(source)
    docstrings = {
        (node.body[0].lineno, node.body[0].col_offset)
        for node in ast.walk(tree)
        if isinstance(node, (ast.FunctionDef, ast.Module, ast.ClassDef))
        and node.body
        and isinstance(node.body[0], ast.Expr)
        and isinstance(node.body[0].value, ast.Constant)
    }
    out = []
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type == tokenize.COMMENT:
            token = token._replace(string=f"# {rng.choice(WORDS)} note")
        elif token.type == tokenize.STRING and token.start in docstrings:
            token = token._replace(string=f'"""My own words about {rng.choice(WORDS)}."""')
        out.append(token)
    return "# written by me\n" + tokenize.untokenize(out)


def _blocks(source: str) -> tuple[list[str], list[str]]:
    lines = source.splitlines()
    tree = ast.parse(source)
    starts = [node.lineno - len(getattr(node, "decorator_list", [])) for node in tree.body]
    head_end = next(
        (
            start
            for start, node in zip(starts, tree.body, strict=True)
            if isinstance(node, (ast.FunctionDef, ast.ClassDef))
        ),
        len(lines) + 1,
    )
    head = lines[: head_end - 1]
    blocks = []
    for index, start in enumerate(starts):
        if start < head_end:
            continue
        end = starts[index + 1] - 1 if index + 1 < len(starts) else len(lines)
        blocks.append("\n".join(lines[start - 1 : end]).rstrip() + "\n")
    return head, blocks


def reordered(source: str, rng: random.Random) -> str:
    head, blocks = _blocks(source)
    shuffled = blocks[:]
    while len(blocks) > 1 and shuffled == blocks:
        rng.shuffle(shuffled)
    return "\n".join(head) + "\n\n" + "\n\n".join(shuffled)


def padded(source: str, rng: random.Random) -> str:
    lines = source.splitlines()
    tree = ast.parse(source)
    inserts: dict[int, list[str]] = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef) and node.body and node.body[0].lineno != node.lineno:
            starts = [
                statement
                for statement in node.body
                if len(lines[statement.lineno - 1]) - len(lines[statement.lineno - 1].lstrip())
                == statement.col_offset
            ]
            for statement in rng.sample(starts, min(2, len(starts))):
                indent = " " * statement.col_offset
                pad = rng.choice(
                    [
                        [f"{indent}unused_{rng.randrange(99)} = {rng.randrange(1000)}"],
                        [f"{indent}if False:", f"{indent}    print('debug {rng.choice(WORDS)}')"],
                        [f"{indent}scratch = [{rng.randrange(9)}] * {rng.randrange(2, 9)}"],
                        [f"{indent}print('checkpoint')"],
                    ]
                )
                inserts.setdefault(statement.lineno, []).extend(pad)
    out = []
    for number, line in enumerate(lines, start=1):
        out.extend(inserts.get(number, []))
        out.append(line)
    return "\n".join(out) + "\n"


def notebook(source: str, rng: random.Random) -> str:
    head, blocks = _blocks(source)
    cells = [{"cell_type": "markdown", "metadata": {}, "source": "# Lab"}]
    for chunk in ["\n".join(head), *blocks, "%matplotlib inline\nprint(blackjack())"]:
        cells.append(
            {
                "cell_type": "code",
                "execution_count": None,
                "metadata": {},
                "outputs": [],
                "source": chunk.strip("\n").splitlines(keepends=True),
            }
        )
    return json.dumps(
        {
            "cells": cells,
            "metadata": {"language_info": {"name": "python"}},
            "nbformat": 4,
            "nbformat_minor": 4,
        }
    )


def combined(source: str, rng: random.Random) -> str:
    return notebook(padded(reordered(comments_changed(renamed(source, rng), rng), rng), rng), rng)


DISGUISES = {
    "renamed": renamed,
    "comments changed": comments_changed,
    "reordered": reordered,
    "dead code padded": padded,
    "notebook": notebook,
    "all five at once": combined,
}


def _with_template(path: Path) -> str:
    text = path.read_text(encoding="utf-8")
    head, blocks = _blocks(text)
    return "\n".join(head) + "\n\n" + FIND_QVALUES + "\n" + "\n\n".join(blocks)


def detection(run_copydetect: bool) -> list[tuple[str, dict[str, tuple[int, int, int, int, float, float]]]]:
    rows = []
    for name, disguise in DISGUISES.items():
        rng = random.Random(f"similarity bench {name}")
        with tempfile.TemporaryDirectory() as folder:
            klass = Path(folder) / "class"
            klass.mkdir()
            copied = set()
            for base in BASES:
                original = _with_template(base)
                (klass / f"{base.stem}.py").write_text(original, encoding="utf-8")
                suffix = ".ipynb" if name in ("notebook", "all five at once") else ".py"
                (klass / f"copy_of_{base.stem}{suffix}").write_text(disguise(original, rng), encoding="utf-8")
                copied.add(frozenset((base.stem, f"copy_of_{base.stem}")))
            identities = sorted(path.stem for path in klass.iterdir())
            results = {"gymgrade": _gymgrade(klass, copied, identities)}
            if run_copydetect:
                results["copydetect"] = _copydetect(klass, Path(folder), copied, identities)
        rows.append((name, results))
    return rows


def _summary(
    scores: dict[frozenset[str], float],
    flagged: set[frozenset[str]],
    copied: set[frozenset[str]],
    identities: list[str],
    universe=None,
):
    pairs = universe if universe is not None else [frozenset(pair) for pair in combinations(identities, 2)]
    independent = [pair for pair in pairs if pair not in copied]
    found = sum(pair in flagged for pair in copied)
    false = sum(pair in flagged for pair in independent)
    lowest_copied = min(scores.get(pair, 0.0) for pair in copied)
    highest_independent = max(scores.get(pair, 0.0) for pair in independent)
    return found, len(copied), false, len(independent), lowest_copied, highest_independent


def _gymgrade(klass: Path, copied, identities, references=(), universe=None):
    import grader.classroom.similarity.run as run_module
    from grader.classroom.similarity.compare import all_scores

    captured = []
    build = run_module.build_report
    run_module.build_report = lambda documents, *a, **k: (
        captured.extend(documents),
        build(documents, *a, **k),
    )[1]
    try:
        report = run_similarity(klass, list(references)).report
    finally:
        run_module.build_report = build
    scores = all_scores(captured)
    flagged = {frozenset((pair.a, pair.b)) for pair in report.pairs}
    return _summary(scores, flagged, copied, identities, universe)


def _copydetect(
    klass: Path,
    folder: Path,
    copied,
    identities,
    references=(),
    identity=lambda path: path.stem,
    universe=None,
):
    import contextlib
    import os

    from copydetect import CopyDetector

    boilerplate = folder / "boilerplate"
    boilerplate.mkdir()
    for path in BUNDLED:
        (boilerplate / path.name.removesuffix(".txt")).write_text(
            path.read_text(encoding="utf-8"), encoding="utf-8"
        )
    with open(os.devnull, "w") as null, contextlib.redirect_stdout(null), contextlib.redirect_stderr(null):
        detector = CopyDetector(
            test_dirs=[str(klass)],
            ref_dirs=[str(klass), *map(str, references)],
            boilerplate_dirs=[str(boilerplate)],
            extensions=["py", "ipynb"],
            autoopen=False,
            silent=True,
            out_file=str(folder / "report.html"),
        )
        detector.run()
    scores: dict[frozenset[str], float] = {}
    for i, test in enumerate(detector.test_files):
        for j, ref in enumerate(detector.ref_files):
            if test == ref:
                continue
            pair = frozenset((identity(Path(test)), identity(Path(ref))))
            if len(pair) < 2:
                continue
            scores[pair] = max(scores.get(pair, 0.0), float(max(detector.similarity_matrix[i, j])))
    flagged = {pair for pair, score in scores.items() if score >= detector.conf.display_t}
    return _summary(scores, flagged, copied, identities, universe)


STATEMENTS = [
    "{a} = {b} + {n}",
    "{a} = env.step({b})[0]",
    "{a} = np.argmax(q_table[{b}])",
    "{a} += {b} * {f}",
    "{a} = [{b} for {c} in range({n})]",
    "{a}, {b} = env.reset(), {n}",
    "{a} = max({a}, {b} - {f})",
    "{a} = random.uniform(0, {n}) < {f}",
    "{a} = {b}[{n}] if {c} > {f} else {b}[0]",
    "{a}.append({b} ** 2)",
    "{a} = sum({b}) / max(len({b}), 1)",
    "{a} = env.action_space.sample()",
    "{a} = np.zeros(({n}, {n}))",
]


def synthetic(rng: random.Random) -> str:
    lines = ["import gym", "import numpy as np", "import random", ""]
    for function in range(5):
        names = [f"{rng.choice(WORDS)}{rng.randrange(100)}" for _ in range(6)]
        lines.append(f"def {rng.choice(WORDS)}_{function}({names[0]}, {names[1]}={rng.randrange(50)}):")
        lines.extend(f"    {name} = {rng.randrange(10)}" for name in names[2:])
        depth = 1
        for _ in range(rng.randrange(14, 26)):
            template = rng.choice(STATEMENTS)
            a, b, c = rng.sample(names, 3)
            statement = template.format(a=a, b=b, c=c, n=rng.randrange(2, 500), f=round(rng.random(), 3))
            lines.append("    " * depth + statement)
            roll = rng.random()
            if roll < 0.15 and depth < 3:
                lines.append("    " * depth + f"for {c} in range({rng.randrange(2, 100)}):")
                depth += 1
                lines.append("    " * depth + f"{a} = {b} - {rng.randrange(9)}")
            elif roll < 0.25 and depth < 3:
                lines.append("    " * depth + f"if {a} > {b}:")
                depth += 1
                lines.append("    " * depth + f"{b} = {a} * {rng.randrange(9)}")
            elif roll < 0.4 and depth > 1:
                depth -= 1
        lines.append(f"    return {names[2]}")
        lines.append("")
    return "\n".join(lines) + "\n"


def hand_written_corpus(run_copydetect: bool) -> dict[str, tuple[int, int, int, int, float, float]]:
    """Both tools on submissions/similarity as written (class and references, expected.toml's pairs)."""
    import tomllib

    root = CORPUS.parent
    expected = tomllib.loads((root / "expected.toml").read_text(encoding="utf-8"))
    copied = {frozenset(pair) for pair in expected["copied"].values()}
    references = sorted(path for path in (root / "references").iterdir() if path.is_dir())
    students = sorted({path.stem for path in CORPUS.iterdir() if not path.name.startswith(".")})
    reference_names = [
        f"{folder.name}/{file.relative_to(folder).as_posix()}"
        for folder in references
        for file in folder.rglob("*.py")
    ]
    identities = students + reference_names
    pairs = {frozenset(pair) for pair in combinations(identities, 2)}
    pairs -= {frozenset(pair) for pair in combinations(reference_names, 2)}

    def identity(path: Path) -> str:
        if path.is_relative_to(CORPUS):
            parts = path.relative_to(CORPUS).parts
            return parts[0] if len(parts) > 1 else path.stem
        folder = next(folder for folder in references if path.is_relative_to(folder))
        return f"{folder.name}/{path.relative_to(folder).as_posix()}"

    results = {"gymgrade": _gymgrade(CORPUS, copied, identities, references, pairs)}
    if run_copydetect:
        with tempfile.TemporaryDirectory() as folder:
            results["copydetect"] = _copydetect(
                CORPUS, Path(folder), copied, identities, references, identity, pairs
            )
    return results


def _cpu_seconds() -> float:
    """User + system time of this process and of its finished children (the indexing pool's workers)."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def scale(students: int, references: int) -> dict[str, float]:
    rng = random.Random("similarity bench scale")
    with tempfile.TemporaryDirectory() as folder:
        klass, known, cache_dir = Path(folder) / "class", Path(folder) / "known", Path(folder) / "cache"
        klass.mkdir()
        known.mkdir()
        reference_texts = [synthetic(rng) for _ in range(references)]
        for index, text in enumerate(reference_texts):
            (known / f"solution_{index:04d}.py").write_text(text, encoding="utf-8")
        for index in range(students):
            text = renamed(reference_texts[index], rng) if index < 10 else synthetic(rng)
            (klass / f"student_{index:03d}.py").write_text(text, encoding="utf-8")
        started, cpu = time.perf_counter(), _cpu_seconds()
        cold = run_similarity(klass, [known], cache=IndexCache(cache_dir)).report
        cold_seconds, cold_cpu = time.perf_counter() - started, _cpu_seconds() - cpu
        started, cpu = time.perf_counter(), _cpu_seconds()
        warm = run_similarity(klass, [known], cache=IndexCache(cache_dir)).report
        warm_seconds, warm_cpu = time.perf_counter() - started, _cpu_seconds() - cpu
        found = sum(
            1
            for pair in warm.pairs
            if pair.b_is_reference and pair.a.startswith("student_00") and pair.b.endswith(pair.a[-1] + ".py")
        )
        return {
            "cold_seconds": cold_seconds,
            "cold_cpu_seconds": cold_cpu,
            "warm_cpu_seconds": warm_cpu,
            "warm_seconds": warm_seconds,
            "flagged": len(warm.pairs),
            "planted_found": found,
            "same": cold == warm,
            "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        }


def refused_links(count: int) -> tuple[float, int]:
    """Seconds to read a class whose one student hands in a zip of ``count`` link entries, and the lines
    listing what was refused."""
    import zipfile

    from grader.classroom.similarity.sources import submissions_from

    with tempfile.TemporaryDirectory() as folder:
        klass = Path(folder) / "class"
        for name in ("ana", "ben"):
            (klass / name).mkdir(parents=True)
            (klass / name / "opengym.py").write_text("def blackjack(n):\n    return 0\n", encoding="utf-8")
        with zipfile.ZipFile(klass / "ben" / "links.zip", "w") as bundle:
            for number in range(count):
                link = zipfile.ZipInfo(f"l{number}.py")
                link.external_attr = 0o120777 << 16
                bundle.writestr(link, "/etc/passwd")
        started = time.perf_counter()
        sources = submissions_from(klass, scratch=Path(folder) / "scratch")
        return time.perf_counter() - started, len(sources.skipped)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--students", type=int, default=300)
    parser.add_argument("--references", type=int, default=1000)
    parser.add_argument("--skip-copydetect", action="store_true")
    parser.add_argument("--skip-scale", action="store_true")
    parser.add_argument(
        "--scale-only", action="store_true", help="only part 2 (its peak memory is then its own)"
    )
    parser.add_argument(
        "--refused-links", type=int, nargs="+", default=None, metavar="N", help="only part 3, for each N"
    )
    args = parser.parse_args()
    if args.refused_links:
        for count in args.refused_links:
            seconds, listed = refused_links(count)
            print(f"| {count:,} | {seconds:.2f} s | {listed} |")
        return
    if args.scale_only:
        result = scale(args.students, args.references)
        print(f"scale: {args.students} students x {args.references} references: {result}")
        return
    print(
        "| disguise | tool | copied pairs flagged | independent pairs flagged | lowest copied score "
        "| highest independent score |"
    )
    print("|---|---|---|---|---|---|")
    totals: dict[str, list[int]] = {}
    for name, results in detection(not args.skip_copydetect):
        for tool, (found, copied, false, independent, low, high) in results.items():
            print(f"| {name} | {tool} | {found}/{copied} | {false}/{independent} | {low:.2f} | {high:.2f} |")
            total = totals.setdefault(tool, [0, 0, 0, 0])
            total[0] += found
            total[1] += copied
            total[2] += false
            total[3] += independent
    for tool, (found, copied, false, independent) in totals.items():
        print(f"| all | {tool} | {found}/{copied} | {false}/{independent} | | |")
    print("\nhand-written corpus (submissions/similarity):")
    for tool, (found, copied, false, independent, low, high) in hand_written_corpus(
        not args.skip_copydetect
    ).items():
        print(f"| {tool} | {found}/{copied} | {false}/{independent} | {low:.2f} | {high:.2f} |")
    if not args.skip_scale:
        result = scale(args.students, args.references)
        print(f"\nscale: {args.students} students x {args.references} references: {result}")


if __name__ == "__main__":
    main()
