#!/usr/bin/env bash
# The type and lint gate (README's test command and .ci/run run it before the tests): ruff's rules
# and its formatting over the repository, and mypy over the runtime packages (pyproject.toml's
# configuration) held to tools/mypy_budget.txt, which may only go down.
set -euo pipefail
cd "$(dirname "$0")/.."
ruff check .
ruff format --check .
python tools/mypy_ratchet.py
