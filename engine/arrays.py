"""The project's numpy array types, named once.

Every package (engine at the bottom, so input, authoring, games and the launcher may all
import it) annotates arrays with these aliases instead of defining its own ``F =
NDArray[np.float64]``: one spelling per dtype, so a signature says at a glance whether it
takes positions (``F64``), indices (``I64``) or a mask (``Bool``), and mypy tells an index
array passed where floats are expected.

Shapes are not part of numpy's static types; docstrings give them (``[P,J,4]``).
"""

from __future__ import annotations

from typing import TypeAlias

import numpy as np
from numpy.typing import NDArray

__all__ = ["F64", "F32", "I64", "I32", "Intp", "U8", "Bool"]

F64: TypeAlias = NDArray[np.float64]
"""Positions, rotations, weights: the simulation's numbers."""
F32: TypeAlias = NDArray[np.float32]
"""What the GPU reads (vertex and instance data)."""
I64: TypeAlias = NDArray[np.int64]
"""Indices: joints, frames, parents."""
Intp: TypeAlias = NDArray[np.intp]
"""Row numbers as numpy hands them out (``nonzero``, ``argsort``, ``flatnonzero``)."""
I32: TypeAlias = NDArray[np.int32]
"""Triangle indices as GL reads them."""
U8: TypeAlias = NDArray[np.uint8]
"""Images and bytes."""
Bool: TypeAlias = NDArray[np.bool_]
"""Masks."""
