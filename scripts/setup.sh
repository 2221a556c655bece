#!/usr/bin/env bash
# Set up a fresh Debian machine for gymgrade: system packages, then the project and its Python packages.
# Idempotent; safe to run again. Needs root (or sudo) for the Debian packages.
#
# Where the project is installed:
#   - into the interpreter `python3` (or $PYTHON) when pip may install there (pyenv, a virtualenv, ...);
#   - into the project virtualenv $GYMGRADE_VENV (default .venv) when the interpreter is externally
#     managed (PEP 668: Debian's and Ubuntu's own python3), or when GYMGRADE_USE_VENV=1.
# `scripts/run COMMAND...` runs a command with that virtualenv first on PATH when it exists, so the
# README's commands work either way.
set -euo pipefail
cd "$(dirname "$0")/.."

PYTHON="${PYTHON:-python3}"
VENV="${GYMGRADE_VENV:-.venv}"

DEBIAN_PACKAGES=(
  bubblewrap        # the sandbox's namespaces, read-only filesystem and seccomp loading
  python3-seccomp   # compiles the sandbox's seccomp filter (libseccomp bindings)
  libseccomp2
  chromium          # the web page's browser test (Playwright drives Debian's Chromium)
  postgresql        # the service's PostgreSQL storage test
  redis-server      # the Celery broker of the distributed workers (tests start their own)
)

externally_managed() {
  "$PYTHON" - <<'PY'
import os, sys, sysconfig
marker = os.path.join(sysconfig.get_path("stdlib"), "EXTERNALLY-MANAGED")
sys.exit(0 if os.path.exists(marker) and sys.prefix == sys.base_prefix else 1)
PY
}

use_venv=0
if [ "${GYMGRADE_USE_VENV:-0}" = 1 ] || externally_managed; then
  use_venv=1
  DEBIAN_PACKAGES+=(python3-venv)  # Debian's python3 has no venv/ensurepip without it
fi

if command -v apt-get >/dev/null 2>&1; then
  missing=()
  for package in "${DEBIAN_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" || missing+=("$package")
  done
  if ((${#missing[@]})); then
    SUDO=""
    [ "$(id -u)" -eq 0 ] || SUDO="sudo"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  fi
else
  echo "setup: no apt-get here; install bubblewrap and libseccomp yourself for full sandbox isolation" >&2
fi

if ((use_venv)); then
  # System site packages stay visible (Debian's python3-seccomp); everything else goes into the venv.
  [ -x "$VENV/bin/python" ] || "$PYTHON" -m venv --system-site-packages "$VENV"
  PYTHON="$VENV/bin/python"
  echo "setup: installed into the project virtualenv $VENV (the interpreter is externally managed," \
    "or GYMGRADE_USE_VENV=1): run commands through scripts/run, or put $VENV/bin first on PATH" >&2
fi
"$PYTHON" -m pip install --quiet --disable-pip-version-check -e ".[dev,postgres,distributed]"
# The project's bytecode, once: an editable install leaves it to the first run, and a grading's processes
# never write it (nor does any process where PYTHONDONTWRITEBYTECODE is set, as container images often do),
# so each of them (the CLI, every xdist worker) compiled some 200 modules again, about 0.2 s of CPU apiece.
# A source edited later is checked against its time stamp and compiled again, as ever.
"$PYTHON" -m compileall -q -j 0 grader reference api >/dev/null
