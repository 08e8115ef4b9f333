"""Type debt may only shrink: run mypy (pyproject.toml's configuration) and fail when it reports
more errors than ``tools/mypy_budget.txt`` allows, or say to lower the budget when it reports fewer.

The gate's goal is zero; until the last errors are fixed this keeps new code from adding any
(the debt grew 130 -> 161 between two rounds with nothing to stop it).
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

BUDGET = Path(__file__).with_name("mypy_budget.txt")


def error_count(output: str) -> int:
    """The number of errors in mypy's summary line (0 on "Success")."""
    found = re.search(r"Found (\d+) errors? in", output)
    return int(found.group(1)) if found else 0


def main() -> int:
    budget = int(BUDGET.read_text().split()[0])
    run = subprocess.run([sys.executable, "-m", "mypy"], capture_output=True, text=True, check=False)
    if run.returncode not in (0, 1) or ("Success" not in run.stdout and "Found" not in run.stdout):
        print(run.stdout + run.stderr, file=sys.stderr)
        return 2
    count = error_count(run.stdout)
    if count > budget:
        print(run.stdout, end="")
        print(
            f"mypy: {count} errors, over the budget of {budget} (tools/mypy_budget.txt): fix the new ones",
            file=sys.stderr,
        )
        return 1
    if count < budget:
        print(f"mypy: {count} errors, under the budget of {budget}: lower tools/mypy_budget.txt to {count}")
    else:
        print(f"mypy: {count} errors, at the budget")
    return 0


if __name__ == "__main__":
    sys.exit(main())
