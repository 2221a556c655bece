"""The documents are true where they can be run: every runnable block runs, every relative link resolves.

The conventions are documented in docs/index.md: a fenced block with the info string ``sh runnable`` holds
one shell command per line, run from the root of a fresh copy of the repository; a relative link names an
existing file and, with a ``#fragment``, one of its headings.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = (ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")))
RUNNABLE = "sh runnable"
OUTPUT_OPTIONS = frozenset({"--out", "--html", "--output"})
REDIRECTIONS = frozenset({">", ">>", "2>", "2>>", "&>"})
PATH_SUFFIXES = (".py", ".ipynb", ".toml", ".md", ".csv", ".zip", ".json", ".sh", ".txt")
COMMAND_SECONDS = 300
_FENCE = re.compile(r"^ {0,3}(`{3,}|~{3,})(.*)$")
_LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
_INLINE_CODE = re.compile(r"(`+).+?\1")


@dataclass(frozen=True)
class Block:
    """A fenced block of a document."""

    document: Path
    line: int
    info: str
    lines: tuple[str, ...]


@dataclass(frozen=True)
class Command:
    """One line of a runnable block."""

    document: Path
    line: int
    text: str

    @property
    def name(self) -> str:
        return f"{self.document.relative_to(ROOT)}:{self.line}"


def fenced_blocks(document: Path) -> list[Block]:
    """Every fenced block of a Markdown file (a longer fence may hold shorter ones as text)."""
    blocks: list[Block] = []
    opened: tuple[str, str, int] | None = None
    body: list[str] = []
    for number, line in enumerate(document.read_text(encoding="utf-8").splitlines(), start=1):
        match = _FENCE.match(line)
        if match is not None and match[1][0] == "`" and "`" in match[2]:
            match = None  # CommonMark: a backtick fence's info string holds no backtick (this is inline code)
        if opened is None:
            if match is not None:
                opened, body = (match[1], match[2].strip(), number), []
        elif (
            match is not None
            and match[1][0] == opened[0][0]
            and len(match[1]) >= len(opened[0])
            and not match[2].strip()
        ):
            blocks.append(Block(document, opened[2], opened[1], tuple(body)))
            opened = None
        else:
            body.append(line)
    if opened is not None:
        raise ValueError(f"{document.relative_to(ROOT)}:{opened[2]}: a fenced block is never closed")
    return blocks


def runnable_commands(documents: tuple[Path, ...] = DOCUMENTS) -> list[Command]:
    """Each command line of every block marked runnable, with where it is written."""
    commands = []
    for document in documents:
        for block in fenced_blocks(document):
            if block.info != RUNNABLE:
                continue
            for offset, text in enumerate(block.lines, start=1):
                if text.strip() and not text.lstrip().startswith("#"):
                    commands.append(Command(document, block.line + offset, text.strip()))
    return commands


def named_files(command: str) -> list[str]:
    """The repository files a command line names as inputs (outputs and redirection targets left out)."""
    words = shlex.split(command, comments=True)
    named = []
    for index, word in enumerate(words):
        previous = words[index - 1] if index else ""
        if (
            word.startswith("-")
            or previous in OUTPUT_OPTIONS
            or previous in REDIRECTIONS
            or word in REDIRECTIONS
        ):
            continue
        if "=" in word or "://" in word:
            continue
        if "/" in word or word.endswith(PATH_SUFFIXES):
            named.append(word)
    return named


def anchors(document: Path) -> set[str]:
    """GitHub's anchors for the headings of a Markdown file (repeats numbered -1, -2, ...)."""
    seen: dict[str, int] = {}
    found = set()
    fenced = {
        line
        for block in fenced_blocks(document)
        for line in range(block.line, block.line + len(block.lines) + 2)
    }
    for number, line in enumerate(document.read_text(encoding="utf-8").splitlines(), start=1):
        heading = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if heading is None or number in fenced:
            continue
        slug = re.sub(r"[^\w\- ]", "", heading[1].strip().lower()).replace(" ", "-")
        count = seen.get(slug, 0)
        seen[slug] = count + 1
        found.add(slug if count == 0 else f"{slug}-{count}")
    return found


def relative_links(document: Path) -> list[tuple[int, str]]:
    """(line, target) of every link outside code that is not an absolute URL."""
    fenced = {
        line
        for block in fenced_blocks(document)
        for line in range(block.line, block.line + len(block.lines) + 2)
    }
    links = []
    for number, line in enumerate(document.read_text(encoding="utf-8").splitlines(), start=1):
        if number in fenced:
            continue
        for target in _LINK.findall(_INLINE_CODE.sub("", line)):
            if not re.match(r"^[a-z][a-z0-9+.-]*:", target):
                links.append((number, target))
    return links


def link_problem(document: Path, target: str) -> str | None:
    """Why a relative link does not resolve, or None."""
    path_part, _, fragment = target.partition("#")
    destination = (document.parent / path_part).resolve() if path_part else document
    if not destination.exists():
        shown = destination.relative_to(ROOT) if destination.is_relative_to(ROOT) else destination
        return f"{target} names {shown}, which does not exist"
    if fragment and destination.suffix == ".md" and fragment not in anchors(destination):
        known = sorted(anchors(destination))
        return f"{target}: {destination.name} has no heading with the anchor #{fragment}; expected {known}"
    return None


COMMANDS = runnable_commands()


def test_the_documents_mark_runnable_blocks_for_students_instructors_and_operators() -> None:
    marked = {command.document.name for command in COMMANDS}
    assert {"README.md", "students.md", "instructors.md", "operations.md"} <= marked, (
        f"expected runnable blocks (```{RUNNABLE}) in the README and the student, instructor and operations "
        f"guides, found them in {sorted(marked)}"
    )


@pytest.mark.parametrize(
    ("markdown", "expected"),
    [
        (
            "```sh runnable\ngymgrade --help\n\n# a comment\ngymgrade doctor\n```\n",
            ["gymgrade --help", "gymgrade doctor"],
        ),
        ("```\ngymgrade check opengym.py\n```\n", []),
        ("````\n```sh runnable\ngymgrade --help\n```\n````\n", []),
        ("~~~sh runnable\nls\n~~~\n", ["ls"]),
    ],
    ids=["marked", "unmarked", "shown-inside-a-longer-fence", "tildes"],
)
def test_runnable_blocks_are_found_by_their_info_string(
    tmp_path: Path, markdown: str, expected: list[str]
) -> None:
    document = tmp_path / "page.md"
    document.write_text(markdown, encoding="utf-8")
    assert [command.text for command in runnable_commands((document,))] == expected


@pytest.mark.parametrize(
    ("command", "expected"),
    [
        (
            "gymgrade check submissions/classic_complete.py --only random_blackjack --html report.html",
            ["submissions/classic_complete.py"],
        ),
        ("gymgrade grade a/b.zip --out gradebook/ --seed 3", ["a/b.zip"]),
        ("gymgrade check x.ipynb --json > out/report.json", ["x.ipynb"]),
        ("GYMGRADE_BROKER_URL=redis://h:1/0 gymgrade worker", []),
        ("scripts/run gymgrade doctor", ["scripts/run"]),
    ],
    ids=["input-and-output", "out-directory", "redirection", "assignment-and-url", "script"],
)
def test_named_files_are_the_inputs(command: str, expected: list[str]) -> None:
    assert named_files(command) == expected


@pytest.mark.parametrize("command", COMMANDS, ids=[command.name for command in COMMANDS])
def test_each_runnable_command_names_only_existing_files(command: Command) -> None:
    missing = [name for name in named_files(command.text) if not (ROOT / name).exists()]
    assert missing == [], (
        f"{command.name}: `{command.text}` names {missing}, which the repository does not hold"
    )


@pytest.fixture(scope="module")
def fresh_copy(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The repository's tracked and new files (not ignored ones) in a temporary directory."""
    destination = tmp_path_factory.mktemp("docs") / "gymgrade"
    listed = subprocess.run(
        ["git", "-C", str(ROOT), "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        capture_output=True, check=True,
    ).stdout.decode().split("\0")  # fmt: skip
    for name in filter(None, listed):
        if (ROOT / name).is_file():
            (destination / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / name, destination / name)
    return destination


@pytest.mark.slow
@pytest.mark.sandbox
@pytest.mark.parametrize("command", COMMANDS, ids=[command.name for command in COMMANDS])
def test_each_runnable_command_succeeds(command: Command, fresh_copy: Path) -> None:
    environment = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])),
    }
    result = subprocess.run(
        ["bash", "-c", command.text], cwd=fresh_copy, env=environment, capture_output=True, text=True,
        timeout=COMMAND_SECONDS,
    )  # fmt: skip
    assert result.returncode == 0, (
        f"{command.name}: `{command.text}` exited {result.returncode}, expected 0:\n"
        f"{result.stdout[-3000:]}\n{result.stderr[-3000:]}"
    )


@pytest.mark.parametrize(
    "document", DOCUMENTS, ids=[str(document.relative_to(ROOT)) for document in DOCUMENTS]
)
def test_every_relative_link_resolves(document: Path) -> None:
    problems = [
        f"{document.relative_to(ROOT)}:{line}: {problem}"
        for line, target in relative_links(document)
        if (problem := link_problem(document, target)) is not None
    ]
    assert problems == []


@pytest.mark.parametrize(
    ("target", "expected"),
    [
        ("docs/students.md", None),
        ("docs/students.md#notebooks", None),
        ("docs/nowhere.md", "docs/nowhere.md names docs/nowhere.md, which does not exist"),
        ("#two-commands-on-a-fresh-machine", None),
    ],
    ids=["file", "file-and-anchor", "missing-file", "own-anchor"],
)
def test_link_problem_names_what_is_missing(target: str, expected: str | None) -> None:
    assert link_problem(ROOT / "README.md", target) == expected


def test_a_missing_anchor_is_a_problem() -> None:
    problem = link_problem(ROOT / "README.md", "docs/students.md#no-such-heading")
    assert problem is not None and problem.startswith(
        "docs/students.md#no-such-heading: students.md has no heading"
    )
