"""The sandbox works when gymgrade runs from a virtualenv wherever it lives, /tmp included (pipx, CI)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
PROBE = textwrap.dedent(
    """
    import sys
    from pathlib import Path
    from grader.sandbox import Call, IsolationPolicy, Sandbox
    with Sandbox(Path(sys.argv[1]), seed=0, policy=IsolationPolicy.ALLOW_FALLBACK) as sandbox:
        outcome = sandbox.call(Call("random_blackjack", (3,), record_episodes=False))
        print(outcome.status, outcome.value, outcome.message)
    """
)


@pytest.mark.sandbox
def test_a_package_only_the_virtualenv_holds_is_importable_in_the_sandbox(tmp_path: Path) -> None:
    # pytest's tmp_path is under /tmp: the venv sits below the sandbox's own scratch /tmp.
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", "--system-site-packages", str(venv)],
                   check=True)  # fmt: skip
    python = venv / "bin" / "python"
    site = subprocess.run(
        [str(python), "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"],
        check=True, capture_output=True, text=True,
    ).stdout.strip()  # fmt: skip
    (Path(site) / "venv_only").mkdir(parents=True)
    (Path(site) / "venv_only" / "__init__.py").write_text("VALUE = 42\n")
    submission = tmp_path / "opengym.py"
    submission.write_text(
        "import os, venv_only\n\ndef random_blackjack(n):\n"
        "    with open('/tmp/scratch.txt', 'w') as scratch:\n        scratch.write('still writable')\n"
        "    return venv_only.VALUE / 100 + os.stat('/tmp').st_mode % 0o10000\n"
    )
    result = subprocess.run(
        [str(python), "-c", PROBE, str(submission)],
        env={**os.environ, "PYTHONPATH": str(ROOT)}, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert result.stdout.strip() == f"ok {0.42 + 0o1777}", result.stdout + result.stderr  # scratch: 1777
