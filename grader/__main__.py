"""`python -m grader ...`: the `gymgrade` command, for where its console script is blocked or not on PATH
(Windows often); same arguments, output and exit codes."""

import sys

from grader.cli import main

sys.exit(main())
