"""The periodic time warp of MoCurves (SCA 2017 §5.2, thesis §5.4.2) as an OSQP problem.

Dragging keypoint ``i`` of a MoCurve along its curve asks that frame ``i`` show the motion
the original showed at time ``φ(s_c)``. With ``N`` keypoints per cycle at original times
``t_i = i·T/N`` we solve for ``t* = (t*_0 … t*_N)`` — the last entry is the seam: keypoint 0
of the next cycle — minimising::

    w1·E_C + w2·E_T + w3·E_V + w4·E_S,      w1 = w2 = 10⁴·w3 = 10⁴·w4
    E_C = Σ_{i∈C} (t*_i − φ(s_i^c))²              constraints
    E_T = (t*_N − t*_0 − T)²                      period kept
    E_V = Σ_i ((t*_{i+1} − t*_i) − (t_{i+1} − t_i))²  velocities near the original
    E_S = Σ_i ((t*_{i+1} − t*_i) − (t*_i − t*_{i−1}))²  no abrupt speed change, *periodic*:
          the term at i = 0 compares the first gap with the seam gap t*_N − t*_{N−1}
    subject to  t*_{i+1} − t*_i ≥ 0   (i = 0 … N−1, the seam gap included)

Why OSQP with a fixed sparsity pattern: the Hessian is banded plus a few seam entries and
never changes shape while a person drags, so the problem is set up once per keypoint
count; each drag only updates ``P``'s values (which keypoints are constrained), ``q`` and the
bounds, and OSQP restarts from the previous solution (warm start) — the interactive case.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import osqp
import scipy.sparse as sp
from numpy.typing import NDArray

__all__ = ["TimeWarp", "TimeWarpError", "W_STRONG", "W_SOFT"]

F = NDArray[np.float64]

W_STRONG = 1.0e4
"""w1 = w2: constraints and period act as strong constraints."""
W_SOFT = 1.0
"""w3 = w4 = w1 / 10⁴."""


class TimeWarpError(ValueError):
    """Bad time-warp input (keypoint out of range, non-finite time) or a QP that did not solve."""


def _energy_rows(n: int) -> tuple[sp.csr_matrix, sp.csr_matrix, sp.csr_matrix]:
    """Sparse row matrices ``[*, N+1]`` of the period, velocity and speed-variation residuals.

    Sparse on purpose: dense products of these would go through a multithreaded BLAS, which
    on a loaded machine spends milliseconds spinning for a 121×121 product.
    """
    m = n + 1
    period = sp.csr_matrix(([-1.0, 1.0], ([0, 0], [0, n])), shape=(1, m))
    idx = np.arange(n)
    vel = sp.csr_matrix((np.r_[-np.ones(n), np.ones(n)], (np.r_[idx, idx], np.r_[idx, idx + 1])), shape=(n, m))
    # (t_{i+1} − t_i) − (t_i − t_{i−1}) for i = 1 … N−1, and at i = 0 the seam gap stands in
    # for the gap before it: (t_1 − t_0) − (t_N − t_{N−1}).
    inner = np.arange(1, n)
    rows = np.r_[inner, inner, inner, 0, 0, 0, 0]
    cols = np.r_[inner + 1, inner, inner - 1, 1, 0, n, n - 1]
    vals = np.r_[np.ones(n - 1), -2.0 * np.ones(n - 1), np.ones(n - 1), 1.0, -1.0, -1.0, 1.0]
    speed = sp.csr_matrix((vals, (rows, cols)), shape=(n, m))
    return period, vel, speed


class TimeWarp:
    """A reusable, warm-started time-warp QP for ``n`` keypoints per cycle of ``period`` seconds.

    Keep one per MoCurve while the person drags: every :meth:`solve` updates the same OSQP
    object, so after the first solve each re-solve starts from the last answer.
    """

    def __init__(self, n: int, period: float, *, w_strong: float = W_STRONG, w_soft: float = W_SOFT,
                 eps: float = 1e-9, max_iter: int = 20000) -> None:  # fmt: skip
        if n < 3:
            raise TimeWarpError(f"a cycle needs at least 3 keypoints to warp, got {n}")
        if not (np.isfinite(period) and period > 0):
            raise TimeWarpError(f"period must be positive and finite, got {period}")
        self.n, self.period = int(n), float(period)
        self.w_strong, self.w_soft = float(w_strong), float(w_soft)
        self.times = np.arange(n + 1) * (self.period / n)
        """Original keypoint times ``t_0 … t_N`` (``t_N = T`` is the seam)."""
        self._eps, self._max_iter = eps, max_iter
        period_rows, vel, speed = _energy_rows(self.n)
        gaps = np.diff(self.times)
        # Quadratic form ½xᵀPx + qᵀx of everything but E_C (which depends on the drag).
        h = 2.0 * (w_strong * (period_rows.T @ period_rows) + w_soft * (vel.T @ vel) + w_soft * (speed.T @ speed))
        self._q_base = -2.0 * (w_strong * self.period * period_rows.toarray()[0] + w_soft * (vel.T @ gaps))
        # The pattern holds every diagonal entry, since any keypoint may carry a constraint;
        # the +1 marks them and is taken off again (the entries are small integers × weights).
        upper = sp.triu(sp.csc_matrix(h + sp.eye(n + 1)), format="csc")
        upper.sort_indices()
        self._p_rows = upper.indices.copy()
        self._p_indptr = upper.indptr.copy()
        self._p_cols = np.repeat(np.arange(n + 1), np.diff(self._p_indptr))
        self._diag_slot = np.flatnonzero(self._p_rows == self._p_cols)
        self._p_base = upper.data.copy()
        self._p_base[self._diag_slot] -= 1.0
        # Monotonicity: t*_{i+1} − t*_i ≥ 0 for i = 0 … N−1.
        self._a = sp.csc_matrix(sp.diags([-np.ones(n), np.ones(n)], [0, 1], shape=(n, n + 1)))
        self._lower = np.zeros(n)
        self._upper = np.full(n, np.inf)
        self._solver: osqp.OSQP | None = None
        self.last_iterations = 0
        self.last_status = ""

    def _p_data(self, constrained: NDArray[np.bool_]) -> F:
        h = self._p_base.copy()
        h[self._diag_slot] += 2.0 * self.w_strong * constrained.astype(np.float64)
        return h

    def solve(self, constraints: Mapping[int, float], *, min_gap: float = 0.0) -> F:
        """New keypoint times ``t*`` ``[N+1]`` for ``{keypoint: wanted time}`` (seconds).

        Keypoint ``N`` is the seam (keypoint 0 one cycle later); a constraint on 0 is
        mirrored onto it. Wanted times are unwrapped to the representative nearest each
        keypoint's original time, so dragging across the seam never asks for a whole-cycle jump.

        Args:
            constraints: keypoint index in ``0 … N−1`` → the original time it should show.
            min_gap: smallest allowed ``t*_{i+1} − t*_i`` (0 in the paper).

        Raises:
            TimeWarpError: an index out of range, a non-finite time, or OSQP failing.
        """
        n, period = self.n, self.period
        constrained = np.zeros(n + 1, dtype=bool)
        target = np.zeros(n + 1)
        for key, value in constraints.items():
            i = int(key)
            if not 0 <= i < n:
                raise TimeWarpError(f"keypoint {key} is outside 0…{n - 1}")
            v = float(value)
            if not np.isfinite(v):
                raise TimeWarpError(f"keypoint {key}: wanted time {value} is not finite")
            v = self.times[i] + (np.mod(v - self.times[i] + 0.5 * period, period) - 0.5 * period)
            constrained[i], target[i] = True, v
            if i == 0:
                constrained[n], target[n] = True, v + period
        if not constrained.any():
            return self.times.copy()
        p_data = self._p_data(constrained)
        q = self._q_base - 2.0 * self.w_strong * target * constrained
        lower = np.full(n, float(min_gap))
        if self._solver is None:
            p = sp.csc_matrix((p_data, self._p_rows, self._p_indptr), shape=(n + 1, n + 1))
            self._solver = osqp.OSQP()
            # Absolute tolerance only: the strong weights make |q| ~ 10⁴, and a relative test
            # would stop while the soft, low-curvature directions (E_V, E_S) are still off.
            self._solver.setup(p, q, self._a, lower, self._upper, verbose=False, eps_abs=self._eps,
                               eps_rel=0.0, max_iter=self._max_iter, polishing=False,
                               warm_starting=True)  # fmt: skip
        else:
            self._solver.update(q=q, l=lower, u=self._upper, Px=p_data)
        res = self._solver.solve(raise_error=False)
        self.last_status = str(res.info.status)
        self.last_iterations = int(res.info.iter)
        if res.x is None or self.last_status not in ("solved", "solved inaccurate"):
            raise TimeWarpError(f"time-warp QP not solved: {self.last_status}")
        t = np.asarray(res.x, dtype=np.float64)
        # OSQP meets the inequalities to its tolerance; make monotonicity exact.
        return np.maximum.accumulate(t)

    def energy(self, t: F, constraints: Mapping[int, float]) -> dict[str, float]:
        """The four energies of ``t`` (``[N+1]``), for tests and the panel's read-out."""
        period_rows, vel, speed = _energy_rows(self.n)
        e_c = sum((t[i] - v) ** 2 for i, v in constraints.items())
        return {
            "E_C": float(e_c),
            "E_T": float((period_rows @ t)[0] - self.period) ** 2,
            "E_V": float(np.sum((vel @ t - np.diff(self.times)) ** 2)),
            "E_S": float(np.sum((speed @ t) ** 2)),
        }
