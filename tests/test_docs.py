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
import sys
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
    # This checkout's code, and the `gymgrade` script of the interpreter running the tests, come first.
    environment = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])),
        "PATH": os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")]),
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


def shown_gymgrade_commands(document: Path) -> list[tuple[int, list[str]]]:
    """(line, arguments) of every `gymgrade ...` line of every fenced block, runnable or not.

    Continuation lines are joined; `scripts/run`, leading VARIABLE=value assignments, a trailing `&` and
    redirections are taken off, since they are the shell's, not gymgrade's.
    """
    shown = []
    for block in fenced_blocks(document):
        text = "\n".join(block.lines).replace("\\\n", " ")
        for offset, line in enumerate(text.splitlines(), start=1):
            words = shlex.split(line, comments=True) if line.strip() else []
            if words[:1] == ["scripts/run"]:
                words = words[1:]
            while words and re.fullmatch(r"[A-Z_]+=\S*", words[0]):
                words = words[1:]
            if words[:1] != ["gymgrade"]:
                continue
            arguments = []
            for word in words[1:]:
                if word in REDIRECTIONS or word in ("&", "|", "&&", ";"):
                    break
                arguments.append(word)
            shown.append((block.line + offset, arguments))
    return shown


SHOWN = [
    (document, line, arguments)
    for document in DOCUMENTS
    for line, arguments in shown_gymgrade_commands(document)
]


def test_shown_commands_leave_the_shell_out(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text(
        "```\n"
        "GYMGRADE_BROKER_URL=redis://h:1/0 gymgrade serve --port 8000 &\n"
        "scripts/run gymgrade doctor   # a comment\n"
        "gymgrade check a.py --json > report.json\n"
        "gymgrade-other x\n"
        "gymgrade gradescope-seed --bundle z.zip \\\n"
        "    --metadata m.json\n"
        "```\n",
        encoding="utf-8",
    )
    assert [arguments for _, arguments in shown_gymgrade_commands(page)] == [
        ["serve", "--port", "8000"],
        ["doctor"],
        ["check", "a.py", "--json"],
        ["gradescope-seed", "--bundle", "z.zip", "--metadata", "m.json"],
    ]


def test_the_documents_show_gymgrade_commands() -> None:
    assert len(SHOWN) >= 30, f"expected the documents' gymgrade commands, found {len(SHOWN)}"


@pytest.mark.parametrize(
    ("document", "line", "arguments"),
    SHOWN,
    ids=[f"{document.relative_to(ROOT)}:{line}" for document, line, _ in SHOWN],
)
def test_each_shown_gymgrade_command_parses(document: Path, line: int, arguments: list[str]) -> None:
    from grader.cli import build_parser

    try:
        build_parser().parse_args(arguments)
    except SystemExit as exit_:
        assert exit_.code == 0, (
            f"{document.relative_to(ROOT)}:{line}: the parser refuses `gymgrade {shlex.join(arguments)}` "
            "(an option or subcommand the CLI does not have): change the page or the CLI"
        )


def known_variables() -> set[str]:
    """Every GYMGRADE_* variable the code reads: the service's settings and the names the code spells out."""
    from api.settings import Settings

    spelled = set()
    for package in ("grader", "api", "scripts"):
        for path in (ROOT / package).rglob("*"):
            if path.is_file() and path.suffix in ("", ".py", ".sh"):
                spelled |= set(
                    re.findall(r"GYMGRADE_[A-Z_]+", path.read_text(encoding="utf-8", errors="replace"))
                )
    return spelled | {f"GYMGRADE_{name.upper()}" for name in Settings.model_fields}


def test_every_documented_variable_is_one_the_code_reads() -> None:
    known = known_variables()
    unknown = sorted(
        f"{document.relative_to(ROOT)}: {variable}"
        for document in DOCUMENTS
        for variable in set(re.findall(r"GYMGRADE_[A-Z_]+", document.read_text(encoding="utf-8")))
        if variable not in known
    )
    assert unknown == [], "the documents name variables no code reads: correct them"
