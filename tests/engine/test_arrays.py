"""One shared array-type module: no runtime module names its own ``F = NDArray[np.float64]``.

:mod:`engine.arrays` holds the project's array aliases; a module defining its own copy drifts
(``F``, ``F64``, ``_F`` for the same type, an index array typed as floats). Like mypy's error
count and the unexplained ignores, none is left (72 when the shared module came, every
runtime package since). Break it once: add ``G = NDArray[np.float64]`` to any runtime module and
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


def test_no_module_has_its_own_array_alias() -> None:
    own = own_alias_modules()
    assert not own, "modules define their own NDArray alias; import it from engine.arrays:\n" + "\n".join(own)


def test_the_shared_aliases_are_the_dtypes_they_name() -> None:
    assert (arrays.F64, arrays.F32, arrays.I64, arrays.Intp, arrays.I32, arrays.U8, arrays.Bool) == (
        NDArray[np.float64],
        NDArray[np.float32],
        NDArray[np.int64],
        NDArray[np.intp],
        NDArray[np.int32],
        NDArray[np.uint8],
        NDArray[np.bool_],
    )
