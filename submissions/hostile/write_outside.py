"""Hostile: tries to write files everywhere but the scratch directory."""

import os
import sys


def scribble(project_root, marker):
    written = []
    targets = [
        os.path.join(project_root, marker), os.path.join("/work/main", marker), f"/etc/{marker}",
        f"/usr/{marker}", f"/root/{marker}", os.path.join(sys.prefix, marker), f"/submission/{marker}",
        os.path.join(os.path.dirname(os.__file__), marker), f"/{marker}",
    ]
    for target in targets:
        try:
            with open(target, "w") as stream:
                stream.write("pwned")
            written.append(target)
        except OSError:
            pass
    return written


def ok():
    return 42
