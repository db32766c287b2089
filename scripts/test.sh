#!/usr/bin/env bash
# Install everything the test suite needs into .venv, then run it.
# Works on a fresh Debian machine: Python packages from PyPI, and Debian's
# chromium for the browser tests (Playwright cannot download its own here).
# Extra arguments go to pytest, e.g. `bash scripts/test.sh -k parser`.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v chromium >/dev/null 2>&1; then
    echo "scripts/test.sh: installing Debian's chromium for the browser tests"
    if [ "$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo"; fi
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium >/dev/null
fi

python3 -m venv .venv
.venv/bin/python -m pip install -q --upgrade pip
.venv/bin/python -m pip install -q -e ".[test]"

.venv/bin/python -m ruff check .
.venv/bin/python -m ruff format --check .
.venv/bin/python -m mypy
.venv/bin/lint-imports --no-cache
.venv/bin/python -m pytest "$@"
