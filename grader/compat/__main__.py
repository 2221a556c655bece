"""`python -m grader.compat SCRIPT.py [ARGS...]`: run a lab-literal script on gymnasium 1.4."""

from __future__ import annotations

import sys
from pathlib import Path

from .activation import run_script

USAGE = "usage: python -m grader.compat SCRIPT.py [ARGS...]"


def main(argv: list[str]) -> int:
    """Run the script named in `argv` with the layer active; return the exit status."""
    if not argv or argv[0] in ("-h", "--help"):
        print(USAGE, file=sys.stderr if not argv else sys.stdout)
        return 2 if not argv else 0
    script = Path(argv[0])
    if not script.is_file():
        print(f"{USAGE}\nerror: expected a Python file, found no file at {script}", file=sys.stderr)
        return 2
    run_script(script, argv[1:])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
