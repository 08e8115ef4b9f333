"""The periodic time warp of MoCurves (SCA 2017 §5.2, thesis §5.4.2) as a QP on the shared core.

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

Why the dense active-set core (:class:`engine.qp.DenseQP`, DAQP): the Hessian is small
(``N+1`` ≈ 120 rows), never changes shape while a person drags, and at the answer few
monotonicity rows are active, so an active-set method ends in a handful of iterations and
meets the constraints and the optimum exactly, where the ADMM solver this replaces needed
thousands of iterations for a 1e-9 tolerance. The workspace is set up once per keypoint
count; each drag updates the Hessian's diagonal (which keypoints are constrained), the
linear term and the bounds, and starts from the previous active set (warm start).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import scipy.sparse as sp

from engine.qp import DenseQP

__all__ = ["TimeWarp", "TimeWarpError", "W_STRONG", "W_SOFT"]

from engine.arrays import F64 as F

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

    Keep one per MoCurve while the person drags: every :meth:`solve` updates the same QP
    workspace, so after the first solve each re-solve starts from the last active set.
    """

    def __init__(self, n: int, period: float, *, w_strong: float = W_STRONG, w_soft: float = W_SOFT,
                 max_iter: int = 2000) -> None:  # fmt: skip
        if n < 3:
            raise TimeWarpError(f"a cycle needs at least 3 keypoints to warp, got {n}")
        if not (np.isfinite(period) and period > 0):
            raise TimeWarpError(f"period must be positive and finite, got {period}")
        self.n, self.period = int(n), float(period)
        self.w_strong, self.w_soft = float(w_strong), float(w_soft)
        self.times = np.arange(n + 1, dtype=np.float64) * (self.period / n)
        """Original keypoint times ``t_0 … t_N`` (``t_N = T`` is the seam)."""
        period_rows, vel, speed = _energy_rows(self.n)
        gaps = np.diff(self.times)
        # Quadratic form ½xᵀHx + fᵀx of everything but E_C (which depends on the drag).
        h = 2.0 * (w_strong * (period_rows.T @ period_rows) + w_soft * (vel.T @ vel) + w_soft * (speed.T @ speed))
        self._h_base = np.asarray(h.toarray())
        self._f_base = -2.0 * (w_strong * self.period * period_rows.toarray()[0] + w_soft * (vel.T @ gaps))
        # Monotonicity: t*_{i+1} − t*_i ≥ 0 for i = 0 … N−1.
        self._a = np.asarray(sp.diags([-np.ones(n), np.ones(n)], [0, 1], shape=(n, n + 1)).toarray())
        self._qp = DenseQP(n + 1, n, iter_limit=max_iter)
        self.last_iterations = 0
        self.last_status = ""

    def solve(self, constraints: Mapping[int, float], *, min_gap: float = 0.0) -> F:
        """New keypoint times ``t*`` ``[N+1]`` for ``{keypoint: wanted time}`` (seconds).

        Keypoint ``N`` is the seam (keypoint 0 one cycle later); a constraint on 0 is
        mirrored onto it. Wanted times are unwrapped to the representative nearest each
        keypoint's original time, so dragging across the seam never asks for a whole-cycle jump.

        Args:
            constraints: keypoint index in ``0 … N−1`` → the original time it should show.
            min_gap: smallest allowed ``t*_{i+1} − t*_i`` (0 in the paper).

        Raises:
            TimeWarpError: an index out of range, a non-finite time, or the QP not solving.
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
        h = self._h_base.copy()
        h[np.diag_indices(n + 1)] += 2.0 * self.w_strong * constrained
        f = self._f_base - 2.0 * self.w_strong * target * constrained
        res = self._qp.solve(h, f, a=self._a, blo=np.full(n, float(min_gap)), bhi=np.full(n, np.inf))
        self.last_status = res.status.value
        self.last_iterations = res.iterations
        if res.x is None:
            raise TimeWarpError(f"time-warp QP not solved: {self.last_status}")
        # The active set meets the inequalities to 1e-9; make monotonicity exact.
        return np.maximum.accumulate(res.x)

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
