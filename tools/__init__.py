"""Developer tooling: regenerate the shipped recordings, screenshots and picture assets.

``python -m tools.regen [demos|recordings|screenshots|assets|all]`` runs these. Nothing of the
runtime (engine, input, authoring, games) imports this package; a layering test keeps it so.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["REPO"]

#: The checkout this package sits in (the recordings of ``tests/data`` and ``docs/`` live there).
REPO = Path(__file__).resolve().parents[1]
