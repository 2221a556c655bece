"""What the notebook reader pays for IPython's input transformer: importing it, or loading it alone.

    python bench/ipython_transformer.py [--runs 15] [--write]

Each run is a fresh interpreter that times (wall and CPU, inside the process) one way of getting
``inputtransformer2``, after importing what the reader child has imported by then
(`grader.submission.notebook.ipython`): ``import IPython.core.inputtransformer2`` (which runs
``IPython/__init__.py``), or `grader.submission.notebook.ipython.transformer()` (the module and, from IPython
8.15 on, ``IPython.utils.tokenutil``, loaded alone). It also counts the modules the way added and says
whether ``pty`` and ``pexpect`` (which a Windows-shaped interpreter lacks) were among them. The two ways
alternate, so a busy machine slows both alike. `--write` replaces this bench's section of bench/RESULTS.md.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
from datetime import date
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from results_section import replace_section  # noqa: E402

HEADING = "## IPython's transformer loaded alone (issue 34)"
WAYS = {
    "import IPython.core.inputtransformer2": "import IPython.core.inputtransformer2",
    "transformer() (loaded alone)": "ipython.transformer()",
}
PROBE = """
import json, sys, time
from grader.submission.notebook import ipython
before = set(sys.modules)
wall, cpu = time.perf_counter(), time.process_time()
{way}
wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
added = set(sys.modules) - before
print(json.dumps({{"wall": wall, "cpu": cpu, "modules": len(added),
                  "posix_only": sorted(name for name in added if name.split(".")[0] in ("pty", "pexpect")),
                  "ipython_package": "IPython" in sys.modules}}))
"""


def measure(runs: int) -> dict[str, list[dict[str, object]]]:
    """``runs`` probes of each way, alternating."""
    results: dict[str, list[dict[str, object]]] = {name: [] for name in WAYS}
    environment = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])),
    }
    for _ in range(runs):
        for name, way in WAYS.items():
            completed = subprocess.run(
                [sys.executable, "-c", PROBE.format(way=way)],
                capture_output=True, text=True, check=True, cwd=ROOT, env=environment,
            )  # fmt: skip
            results[name].append(json.loads(completed.stdout))
    return results


def section(results: dict[str, list[dict[str, object]]], runs: int) -> str:
    import IPython

    lines = [
        HEADING,
        "",
        f"Measured by `python bench/ipython_transformer.py --runs {runs}` on {date.today().isoformat()} "
        f"(Python {platform.python_version()}, IPython {IPython.__version__}, {os.cpu_count()} cores shared "
        "with other work; load average at the start "
        f"{os.getloadavg()[0]:.1f}): {runs} fresh interpreters per way, alternating, each timing only the "
        "step below after importing `grader.submission.notebook.ipython` (what the reader child pays once "
        "per notebook).",
        "",
        "| way | wall, median (min-max) | CPU, median | modules added | pty, pexpect | __init__ ran |",
        "|---|---|---|---|---|---|",
    ]
    for name, probes in results.items():
        walls = [float(probe["wall"]) * 1000 for probe in probes]  # type: ignore[arg-type]
        cpus = [float(probe["cpu"]) * 1000 for probe in probes]  # type: ignore[arg-type]
        posix = sorted({module.split(".")[0] for probe in probes for module in probe["posix_only"]})  # type: ignore[attr-defined]
        lines.append(
            f"| `{name}` | {statistics.median(walls):.1f} ms ({min(walls):.1f}-{max(walls):.1f}) "
            f"| {statistics.median(cpus):.1f} ms | {probes[0]['modules']} | {', '.join(posix) or 'no'} "
            f"| {'yes' if probes[0]['ipython_package'] else 'no'} |"
        )
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=15)
    parser.add_argument("--write", action="store_true", help=f"replace {HEADING!r} in bench/RESULTS.md")
    arguments = parser.parse_args()
    text = section(measure(arguments.runs), arguments.runs)
    print(text)
    if arguments.write:
        replace_section(HEADING, text + "\n")


if __name__ == "__main__":
    main()
