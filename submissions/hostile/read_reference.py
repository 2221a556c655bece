"""Hostile: reads the reference solutions and the grader's configuration, by path and by searching."""

import os

TARGETS = ("solutions.py", "assignment.toml", "oracles")


def steal(project_root):
    read = []
    for relative in ("reference/solutions.py", "grader/lab/assignment.toml", "reference/__init__.py"):
        for root in (project_root, "/work/main"):
            try:
                with open(os.path.join(root, relative)) as stream:
                    read.append(stream.read()[:100])
            except OSError:
                pass
    found = []
    for directory, subdirectories, files in os.walk("/"):
        if directory == "/":
            subdirectories[:] = [name for name in subdirectories if name not in ("proc", "sys", "dev")]
        found += [os.path.join(directory, name) for name in files + subdirectories if name in TARGETS]
    return {"read": read, "found": found}


def ok():
    return 42
