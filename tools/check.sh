#!/usr/bin/env bash
# The type and lint gate (README's test command and .ci/run run it before the tests): ruff's rules
# and its formatting over the repository, and mypy over the runtime packages (pyproject.toml's
# configuration): each with zero findings.
set -euo pipefail
cd "$(dirname "$0")/.."
ruff check .
ruff format --check .
mypy
