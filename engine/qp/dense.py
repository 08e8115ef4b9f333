"""A dense, warm-started QP workspace on DAQP (a dual active-set solver).

Problem, with ``n`` variables and ``m`` general rows::

    min_x  ½ xᵀ H x + fᵀ x
    s.t.   lo ≤ x ≤ hi            (simple bounds, may be ±inf)
           blo ≤ A x ≤ bhi        (general rows; blo = bhi makes an equality)

Why DAQP: its workspace is allocated once per shape (``daqp.Model.setup``) and each
re-solve only updates the data, starting from the previous active set — exactly the
drag loop of an editor, where consecutive QPs differ a little. Iterations are capped
(``iter_limit``) so one bad QP can never stall a frame; hitting the cap, an
infeasible problem or a numerical failure is reported in :class:`QPStatus`, never
raised, and the workspace is rebuilt on the next solve so a failure does not poison
the warm start.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import daqp
import numpy as np
from numpy.typing import ArrayLike

from engine.arrays import F64 as F

__all__ = ["DenseQP", "QPResult", "QPStatus"]


_INF = 1e30  # DAQP's "no bound"


class QPStatus(Enum):
    """How a solve ended."""

    SOLVED = "solved"
    ITERATION_LIMIT = "iteration limit"
    INFEASIBLE = "infeasible"
    FAILED = "failed"  # unbounded, non-convex, or a numerical breakdown


# DAQP exit flags (https://darnstrom.github.io/daqp/parameters): 1 optimal, 2 soft-optimal,
# -1 infeasible, -2 cycling, -3 unbounded, -4 iteration limit, -5 non-convex, -6 initial
# working set overdetermined.
_FLAGS = {1: QPStatus.SOLVED, 2: QPStatus.SOLVED, -1: QPStatus.INFEASIBLE, -4: QPStatus.ITERATION_LIMIT}


@dataclass(frozen=True)
class QPResult:
    """One solve: the minimiser (``None`` unless solved), its status and the iterations spent."""

    x: F | None
    status: QPStatus
    iterations: int

    @property
    def ok(self) -> bool:
        """True when ``x`` is a solution."""
        return self.x is not None


class DenseQP:
    """A reusable QP of ``n`` variables and ``m`` general rows (set up once, warm-started after).

    Args:
        n: number of variables; m: number of general rows (may be 0).
        iter_limit: active-set iterations per solve before giving up.
        primal_tol: how far a constraint may be violated at the answer.
    """

    def __init__(self, n: int, m: int = 0, *, iter_limit: int = 1000, primal_tol: float = 1e-9) -> None:
        if n < 1 or m < 0:
            raise ValueError(f"a QP needs n ≥ 1 variables and m ≥ 0 rows, got n={n}, m={m}")
        self.n, self.m = int(n), int(m)
        self._settings = {"iter_limit": int(iter_limit), "primal_tol": float(primal_tol)}
        self._model: daqp.Model | None = None
        self._empty_a = np.zeros((0, self.n))
        self._equal = np.zeros(0, dtype=bool)
        self.solves = 0
        self.last: QPResult | None = None

    def reset(self) -> None:
        """Forget the warm start (the next solve sets the workspace up afresh)."""
        self._model = None

    def solve(
        self,
        h: ArrayLike,
        f: ArrayLike,
        lo: ArrayLike | None = None,
        hi: ArrayLike | None = None,
        a: ArrayLike | None = None,
        blo: ArrayLike | None = None,
        bhi: ArrayLike | None = None,
    ) -> QPResult:
        """Solve for the given data (shapes fixed at construction); ``None`` bounds are unbounded."""
        n, m = self.n, self.m
        hm = np.ascontiguousarray(h, dtype=np.float64).reshape(n, n)
        fv = np.ascontiguousarray(f, dtype=np.float64).reshape(n)
        am = self._empty_a if m == 0 else np.ascontiguousarray(a, dtype=np.float64).reshape(m, n)
        upper = np.empty(n + m)
        lower = np.empty(n + m)
        upper[:n] = _INF if hi is None else np.minimum(np.asarray(hi, dtype=np.float64).reshape(n), _INF)
        lower[:n] = -_INF if lo is None else np.maximum(np.asarray(lo, dtype=np.float64).reshape(n), -_INF)
        if m:
            upper[n:] = _INF if bhi is None else np.minimum(np.asarray(bhi, dtype=np.float64).reshape(m), _INF)
            lower[n:] = -_INF if blo is None else np.maximum(np.asarray(blo, dtype=np.float64).reshape(m), -_INF)
        if not (np.isfinite(hm).all() and np.isfinite(fv).all() and np.isfinite(am).all()):
            return self._done(None, QPStatus.FAILED, 0)
        if np.any(lower > upper):
            return self._done(None, QPStatus.INFEASIBLE, 0)
        equal = lower == upper
        if self._model is None or not np.array_equal(equal, self._equal):
            # New workspace, or a new equality pattern (the constraint senses also carry the
            # active set, so they are only re-sent when they must change).
            sense = np.where(equal, 5, 0).astype(np.int32)
            self._model = daqp.Model()
            self._model.settings = self._settings
            self._model.setup(hm, fv, am, upper, lower, sense)
            self._equal = equal
        elif m:
            self._model.update(H=hm, f=fv, A=am, bupper=upper, blower=lower)
        else:
            self._model.update(H=hm, f=fv, bupper=upper, blower=lower)
        x, _, flag, info = self._model.solve()
        self.solves += 1
        status = _FLAGS.get(int(flag), QPStatus.FAILED)
        iters = int(info.get("iterations", 0)) if isinstance(info, dict) else 0
        if status is not QPStatus.SOLVED:
            self._model = None  # a failed workspace is not a good warm start
            return self._done(None, status, iters)
        xv = np.array(x, dtype=np.float64)
        if not np.isfinite(xv).all():
            self._model = None
            return self._done(None, QPStatus.FAILED, iters)
        return self._done(xv, status, iters)

    def _done(self, x: F | None, status: QPStatus, iterations: int) -> QPResult:
        self.last = QPResult(x, status, iterations)
        return self.last
