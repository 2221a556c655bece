"""API contract figures: cases schemathesis generates, failures it finds, and the time the test takes.

Runs what ``tests/api/test_contract.py`` runs (the same server set-up and schemathesis settings, from
``tests/api/contract.py``) once per token, then the test itself under pytest for its wall time, and prints
the ``## API contract (issue 15)`` section of bench/RESULTS.md. Usage: ``python bench/contract.py``.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import time
from datetime import date
from importlib.metadata import version
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TESTS_API = ROOT / "tests" / "api"
sys.path[:0] = [str(ROOT), str(TESTS_API)]

from contract import (  # noqa: E402  (the test helpers live beside the tests)
    CONTRACT_SERVER_SETTINGS,
    PHASES,
    SCHEMATHESIS_CONFIG,
    ContractRun,
    caller_tokens,
    run_schemathesis,
    start_contract_server,
)

STATEFUL = re.compile(r"Scenarios:\s+(\d+)")
LINKS = re.compile(r"API Links:\s+(\d+) covered / (\d+) selected")
MAX_EXAMPLES = re.compile(r"^max-examples\s*=\s*(\d+)", re.MULTILINE)


def contract_runs() -> tuple[list[ContractRun], float]:
    """Both schemathesis runs against one fresh server, and the wall time of all of it."""
    started = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="gymgrade-contract-") as directory:
        server = start_contract_server(Path(directory))
        try:
            tokens = caller_tokens(server)
            runs = [
                run_schemathesis(server.url, caller, tokens[caller], Path(directory) / f"{caller}.json")
                for caller in ("student", "instructor")
            ]
        finally:
            server.stop()
    return runs, time.monotonic() - started


def pytest_seconds() -> tuple[float, str]:
    """Wall time of ``python -m pytest tests/api/test_contract.py`` and its last line."""
    paths = [str(ROOT), *filter(None, os.environ.get("PYTHONPATH", "").split(os.pathsep))]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(paths)}
    started = time.monotonic()
    finished = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "tests/api/test_contract.py"],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    last = (finished.stdout.strip().splitlines() or ["(no output)"])[-1]
    return time.monotonic() - started, last


def _row(run: ContractRun) -> str:
    scenarios = STATEFUL.search(run.output)
    links = LINKS.search(run.output)
    phases = ", ".join(f"{name} {run.phases.get(name, '?')}" for name in PHASES)
    return (
        f"| {run.caller} | {run.cases} | {run.failures} | {run.errors} | {phases} | "
        f"{scenarios.group(1) if scenarios else '?'} | "
        f"{f'{links.group(1)} of {links.group(2)}' if links else '?'} | {run.seconds:.1f} s |"
    )


def main() -> int:
    """Measure and print the section."""
    load = os.getloadavg()[0]
    runs, total = contract_runs()
    for run in runs:
        print(f"{run.caller}: {run.cases} cases, {run.failures} failing", file=sys.stderr)
    test_wall, test_summary = pytest_seconds()
    examples = MAX_EXAMPLES.search(SCHEMATHESIS_CONFIG.read_text(encoding="utf-8"))
    settings = ", ".join(f"{name} {value}" for name, value in CONTRACT_SERVER_SETTINGS.items())
    print(f"""## API contract (issue 15)

`python bench/contract.py`: schemathesis {version("schemathesis")}, `--checks all`, phases
{", ".join(PHASES)}, at most {examples.group(1) if examples else "?"} examples per operation and phase
(`tests/api/schemathesis.toml`), against `gymgrade serve` on loopback with the fake grader ({settings}):
the set-up of `tests/api/test_contract.py`. 2 cores shared with other jobs, 1-minute load average
{load:.1f} when started, {date.today().isoformat()}.

| token | cases generated | failing cases | errors | phases | stateful scenarios | links covered | time |
|-------|-----------------|---------------|--------|--------|--------------------|---------------|------|
{chr(10).join(_row(run) for run in runs)}

- Failures found: **{sum(run.failures for run in runs)}** in {sum(run.cases for run in runs)} generated cases
  (goal 0).
- Both runs with the server's start and stop: {total:.1f} s; the test under pytest
  (`python -m pytest tests/api/test_contract.py`): **{test_wall:.1f} s** wall ({test_summary}).""")
    return 0 if all(run.clean for run in runs) else 1


if __name__ == "__main__":
    sys.exit(main())
