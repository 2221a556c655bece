"""Lines of code and modules of `grader/` and `api/` at two git revisions (issue 11's structure figures).

A line of code is a line of a `.py` file that holds a token other than a comment (docstrings count: they
are part of the code a reader reads); blank lines and comment-only lines do not. Each revision is read
from git (`git ls-tree` and `git show`), so the work tree is never touched.

    python bench/structure.py [BEFORE [AFTER]]     # default: main and HEAD
"""

from __future__ import annotations

import argparse
import io
import statistics
import subprocess
import tokenize
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("grader", "api")
_NOT_CODE = frozenset({tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT})


def code_lines(source: str) -> int:
    """The lines of `source` holding a token other than a comment (a multi-line string counts each line)."""
    lines: set[int] = set()
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type not in _NOT_CODE and token.type != tokenize.ENDMARKER:
            lines.update(range(token.start[0], token.end[0] + 1))
    return len(lines)


def _git(*args: str) -> str:
    return subprocess.run(["git", *args], cwd=ROOT, check=True, capture_output=True, text=True).stdout


@dataclass(frozen=True)
class Structure:
    """The Python modules of the packages at one revision and their lines of code."""

    revision: str
    lines: dict[str, int]

    @classmethod
    def at(cls, revision: str) -> Structure:
        """Read every `.py` file of the packages at a git revision."""
        paths = _git("ls-tree", "-r", "--name-only", revision, "--", *PACKAGES).split()
        modules = [path for path in paths if path.endswith(".py")]
        return cls(revision, {path: code_lines(_git("show", f"{revision}:{path}")) for path in modules})

    def row(self, package: str | None = None) -> str:
        """Modules, lines, median and largest module of one package (all of them when None)."""
        chosen = [path for path in self.lines if package is None or path.startswith(f"{package}/")]
        sizes = {path: self.lines[path] for path in chosen}
        largest = max(sizes, key=sizes.__getitem__)
        return (
            f"{package or 'total':<7} {len(sizes):>7} {sum(sizes.values()):>7} "
            f"{statistics.median(sizes.values()):>7.0f}  {largest} ({sizes[largest]})"
        )


def main() -> None:
    """Print both revisions' figures and what changed, module by module."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before", nargs="?", default="main")
    parser.add_argument("after", nargs="?", default="HEAD")
    args = parser.parse_args()
    before, after = Structure.at(args.before), Structure.at(args.after)
    for structure in (before, after):
        print(f"{structure.revision}:\n{'package':<7} {'modules':>7} {'lines':>7} {'median':>7}  largest")
        for package in (*PACKAGES, None):
            print(structure.row(package))
    print(f"change {args.before} -> {args.after}:")
    for path in sorted(before.lines.keys() | after.lines.keys()):
        old, new = before.lines.get(path, 0), after.lines.get(path, 0)
        if old != new:
            print(f"  {new - old:+5d}  {path} ({old} -> {new})")


if __name__ == "__main__":
    main()
