"""`python -m grader.cli`: the `gymgrade` command."""

import sys

from grader.cli import main

sys.exit(main())
