"""GitHub Classroom, as ``gh classroom clone student-repos`` writes it:
``{assignment-slug}-submissions/{assignment-prefix}-{github-username}/...``.

The student is the GitHub username: the repository folder's name after the assignment prefix (the slug,
or the prefix every repository folder shares). The classroom roster joins usernames to names. The time is
the committer time of the repository's checked-out commit (``grader.classroom.git_commit``), when its
``.git`` folder is there to read.
"""

from __future__ import annotations

import os
from collections import defaultdict

from grader.classroom.git_commit import commit_time
from grader.classroom.layouts.protocol import Group, Grouping, top_names
from grader.classroom.model import Member, Skipped
from grader.classroom.tree import Entry, Tree

SUFFIX = "-submissions"


def _base(tree: Tree) -> tuple[int, str]:
    """How many leading components to skip (a single ``*-submissions`` folder) and the slug it names."""
    names = top_names(tree)
    if len(names) == 1 and next(iter(names)).endswith(SUFFIX):
        return 1, next(iter(names))[: -len(SUFFIX)]
    return 0, tree.root.name[: -len(SUFFIX)] if tree.root.name.endswith(SUFFIX) else ""


def _repositories(tree: Tree, skip: int) -> set[str]:
    return {entry.parts[skip] for entry in tree.entries if len(entry.parts) > skip + 1}


def repository_prefix(repositories: set[str], slug: str) -> str:
    """The prefix of every repository folder: ``{slug}-`` when all share it, else their common prefix up to
    its last ``-`` ("" when they share none)."""
    if slug and repositories and all(name.startswith(f"{slug}-") for name in repositories):
        return f"{slug}-"
    if len(repositories) < 2:
        return ""
    common = os.path.commonprefix(sorted(repositories))  # noqa: RUF071 - names, compared character by character
    return common[: common.rfind("-") + 1] if "-" in common else ""


class GitHubClassroomLayout:
    """See the module docstring."""

    name = "github-classroom"
    title = "GitHub Classroom (gh classroom clone student-repos)"

    def score(self, tree: Tree) -> float:
        """High under a ``*-submissions`` folder; middling when repository folders share a prefix."""
        skip, slug = _base(tree)
        repositories = _repositories(tree, skip)
        if not repositories:
            return 0.0
        prefix = repository_prefix(repositories, slug)
        if slug and prefix:
            return 0.95
        return 0.3 if prefix else 0.0

    def group(self, tree: Tree) -> Grouping:
        """A group per repository folder, the username its name after the prefix."""
        skip, slug = _base(tree)
        prefix = repository_prefix(_repositories(tree, skip), slug)
        grouping = Grouping()
        files: dict[str, list[tuple[Entry, str]]] = defaultdict(list)
        for entry in tree.entries:
            if len(entry.parts) <= skip + 1 or not entry.parts[skip].startswith(prefix):
                grouping.unattributed.append(
                    Skipped(
                        entry.relative, f"not inside a {prefix or '{prefix}-'}{{username}} repository folder"
                    )
                )
                continue
            username = entry.parts[skip][len(prefix) :]
            files[username].append((entry, "/".join(entry.parts[skip + 1 :])))
        for username, found in sorted(files.items()):
            entry = found[0][0]
            repository = entry.path.parents[len(entry.parts) - skip - 2]
            grouping.groups.append(Group((Member(username),), found, submitted_at=commit_time(repository)))
        return grouping
