"""Start the child harness inside the sandbox.

Command (as a script path it works under `-I`, which ignores PYTHONPATH)::

    <python> -I -B <root>/grader/sandbox/child/__main__.py --submission PATH --requests FD --results FD
        [--max-frame BYTES] [--seed INT] [--max-recorded-steps N]

`<root>` is the directory holding `grader/` (with `grader/compat/`); run as a script, it is put on
`sys.path` here. Run as a module (`runpy.run_module("grader.sandbox.child", run_name="__main__")`
with `sys.path` prepared, as the sandbox's bootstrap does), nothing is added. FD are inherited pipe
ends: call frames are read from `--requests`, result frames written to `--results`; the student's
output goes to fds 1 and 2. `--seed` seeds randomness while the submission is imported. The
environment variables below are set before numpy is imported so that BLAS runs one thread and
nothing opens a window.
"""

import os
import sys
from pathlib import Path

CHILD_ENVIRONMENT = {
    "MPLBACKEND": "Agg",
    "OPENBLAS_NUM_THREADS": "1",
    "OMP_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "SDL_VIDEODRIVER": "dummy",
    "SDL_AUDIODRIVER": "dummy",
    "PYGAME_HIDE_SUPPORT_PROMPT": "1",
}

os.environ.update(CHILD_ENVIRONMENT)
if not __package__:
    sys.path.insert(0, str(Path(__file__).resolve().parents[3]))

from grader.sandbox.child.harness import main  # noqa: E402

if __name__ == "__main__":
    status = main()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError, AttributeError):
            continue
    # Without the interpreter's finalisation: tearing down numpy, gymnasium and the student's objects cost
    # each child 25-50 ms of CPU after its last call, which nothing reads (bench/RESULTS.md `## Class
    # throughput`). The student's exit handlers and threads end with it; the runner kills what is left.
    os._exit(status)
