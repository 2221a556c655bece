#!/usr/bin/env bash
# Set up a fresh Debian machine for gymgrade: system packages, then the project and its Python packages.
# Idempotent; safe to run again. Needs root (or sudo) for the Debian packages.
set -euo pipefail
cd "$(dirname "$0")/.."

DEBIAN_PACKAGES=(
  bubblewrap        # the sandbox's namespaces, read-only filesystem and seccomp loading
  python3-seccomp   # compiles the sandbox's seccomp filter (libseccomp bindings)
  libseccomp2
  chromium          # the web page's browser test (Playwright drives Debian's Chromium)
  postgresql        # the service's PostgreSQL storage test
  redis-server      # the Celery broker of the distributed workers (tests start their own)
)

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

python3 -m pip install --quiet --disable-pip-version-check -e ".[dev,postgres,distributed]"
