#!/usr/bin/env bash
# Install everything the test suite needs into .venv, then run it.
# Works on a fresh Debian machine: Python packages from PyPI, and Debian's
# chromium for the browser tests (Playwright cannot download its own here).
# Extra arguments go to pytest, e.g. `bash scripts/test.sh -k parser`.
# pytest runs on every core (pytest-xdist, `-n auto`); `--dist loadgroup` keeps the
# tests marked `xdist_group("default_ports")` (they use 31000/64444/9090/8080) on one
# worker, one at a time. `C2RVIZ_TEST_WORKERS=1` runs it in one process.
# A run that collects no test fails (pytest's status 5), e.g. a `-k` that matches nothing.
# The 30 slowest tests are listed at the end: where the suite's minutes go.
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
# The programs the tests start (about a hundred) would each compile c2rviz again where
# PYTHONDONTWRITEBYTECODE is set: compiled once here, each start is ~0.26 s quicker. And
# the run itself writes its caches (pytest's rewritten test and plugin modules, which
# each of the ~15 pytest processes the tests start would rewrite again, ~0.6 s each).
.venv/bin/python -m compileall -q c2rviz
unset PYTHONDONTWRITEBYTECODE
workers=(-n "${C2RVIZ_TEST_WORKERS:-auto}" --dist loadgroup)
if [ "${C2RVIZ_TEST_WORKERS:-auto}" = "1" ]; then workers=(-p no:xdist); fi

# `--cov` (or C2RVIZ_COVERAGE=1): branch coverage of c2rviz/ ([tool.coverage.*] in
# pyproject.toml), the programs the tests start included, printed at the end. A whole
# run (no other arguments) also fails below the floor the docs give (docs/testing.md).
COVERAGE_FLOOR=92  # a little below the 93.5 % measured (docs/testing.md)
cov=()
args=()
for arg in "$@"; do
    if [ "$arg" = "--cov" ]; then C2RVIZ_COVERAGE=1; else args+=("$arg"); fi
done
if [ "${C2RVIZ_COVERAGE:-0}" = "1" ]; then
    export COVERAGE_FILE="$PWD/.coverage"  # the children's data too, whatever their cwd
    rm -f .coverage .coverage.*
    cov=(--cov --cov-report=term:skip-covered --cov-report=xml)
    if [ "${#args[@]}" -eq 0 ]; then cov+=(--cov-fail-under="$COVERAGE_FLOOR"); fi
fi

status=0
.venv/bin/python -m pytest "${workers[@]}" --durations=30 "${cov[@]}" "${args[@]}" || status=$?
if [ "$status" -eq 5 ]; then
    echo "scripts/test.sh: pytest collected no test: that is a failure, not a pass" >&2
fi
exit "$status"
