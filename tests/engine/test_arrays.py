"""One shared array-type module: the modules that still name their own ``F = NDArray[np.float64]`` only get fewer.

:mod:`engine.arrays` holds the project's array aliases; a module defining its own copy drifts
(``F``, ``F64``, ``_F`` for the same type, an index array typed as floats). Like mypy's error
count and the unexplained ignores, the copies left are held to a budget that may only go down:
72 when the shared module came (engine's own packages outside render, blend, ik and the state
machine moved to it). Break it once: add ``G = NDArray[np.float64]`` to any runtime module and
the second test fails naming that file.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from engine import arrays

ROOT = Path(__file__).resolve().parents[2]
RUNTIME = ("engine", "input", "authoring", "games", "puppetphone")
OWN_ALIAS = re.compile(r"^_?\w+(\s*:\s*TypeAlias)?\s*=\s*(npt\.)?NDArray\[", re.M)
LOCAL_ALIAS_BUDGET = 72  # lower it as modules import engine.arrays instead; never raise it


def own_alias_modules() -> list[str]:
    """Runtime modules (other than engine/arrays.py) that define an NDArray alias of their own."""
    shared = Path(arrays.__file__).resolve()
    return [
        str(path.relative_to(ROOT))
        for package in RUNTIME
        for path in sorted((ROOT / package).rglob("*.py"))
        if path.resolve() != shared and OWN_ALIAS.search(path.read_text(encoding="utf-8"))
    ]


def test_the_rule_sees_an_own_alias_and_not_an_import_or_an_annotation() -> None:
    assert OWN_ALIAS.search("import numpy as np\nF = NDArray[np.float64]\n")
    assert OWN_ALIAS.search("_Idx: TypeAlias = NDArray[np.int64]\n")
    assert not OWN_ALIAS.search("from engine.arrays import F64 as F\n")
    assert not OWN_ALIAS.search("def f(x: NDArray[np.float64]) -> None: ...\n    y = NDArray[np.float64]\n")


def test_modules_with_their_own_array_alias_only_get_fewer() -> None:
    own = own_alias_modules()
    assert len(own) <= LOCAL_ALIAS_BUDGET, (
        f"{len(own)} modules define their own NDArray alias, over the budget of {LOCAL_ALIAS_BUDGET}; "
        "import them from engine.arrays:\n" + "\n".join(own)
    )


def test_the_shared_aliases_are_the_dtypes_they_name() -> None:
    assert (arrays.F64, arrays.F32, arrays.I64, arrays.I32, arrays.U8, arrays.Bool) == (
        NDArray[np.float64],
        NDArray[np.float32],
        NDArray[np.int64],
        NDArray[np.int32],
        NDArray[np.uint8],
        NDArray[np.bool_],
    )
