"""One linearised IK step as an OSQP problem with a fixed sparsity pattern.

Each iteration of the optimisation IK solves (thesis Eq. 4.13 with the ε band of
Eq. 4.11 and the regulariser λ of §4.2.3)::

    min_Δc  w_m‖Δs − J_s Δc‖² + w_d‖D Δc‖² + λ‖Δc‖²
    s.t.    Δρ' − ε ≤ J_ρ Δc ≤ Δρ' + ε          (pins)
            max(u − c, −r) ≤ Δc ≤ min(v − c, r)    (limits, and a trust radius r)

Written as-is, ``P = 2(w_m J_sᵀJ_s + …)`` is a dense ``n×n`` matrix and OSQP's
factorisation of it dominates the solve at 168 coordinates. We give OSQP the
equivalent sparse form instead: an auxiliary ``y = J_s Δc`` (one variable per
effector row) turns the objective into ``w_m‖Δs − y‖² + Δcᵀ(w_d D² + λ)Δc``, whose
``P`` is diagonal, and ``J_s Δc − y = 0`` joins the constraints. The KKT system then
stays sparse (``O(n·rows)``), and since the pattern never changes the problem is set
up once and only its values are updated, keeping OSQP's symbolic factorisation and
its warm start between iterations.
"""

from __future__ import annotations

import numpy as np
import osqp
import scipy.sparse as sp
from numpy.typing import NDArray

__all__ = ["StepQP"]

F = NDArray[np.float64]


class StepQP:
    """A reusable QP of ``n`` coordinates, ``r`` effector rows and ``m`` pin rows."""

    def __init__(self, n: int, r: int, m: int, *, eps: float = 1e-6, max_iter: int = 10000) -> None:
        self.n, self.r, self.m = n, r, m
        # A = [[J_s, -I_r], [J_rho, 0], [I_n, 0]]; CSC column by column.
        rows_c = np.r_[np.arange(r + m), 0][None, :] + np.zeros((n, 1), np.int64)
        rows_c[:, -1] = r + m + np.arange(n)
        rows = np.concatenate([rows_c.reshape(-1), np.arange(r)])
        indptr = np.r_[np.arange(n + 1) * (r + m + 1), n * (r + m + 1) + np.arange(1, r + 1)]
        self._a_pattern = (rows.astype(np.int64), indptr.astype(np.int64))
        self._solver: osqp.OSQP | None = None
        self._eps = eps
        self._max_iter = max_iter

    def _a_data(self, js: F, jrho: F) -> F:
        block = np.vstack([js, jrho, np.ones((1, self.n))])  # [r+m+1, n]
        return np.concatenate([block.T.reshape(-1), -np.ones(self.r)])

    def solve(self, w_m: float, diag: F, js: F, ds: F, jrho: F, band_lo: F, band_hi: F, lo: F, hi: F) -> F | None:
        """The step ``Δc`` of the QP above, or ``None`` when OSQP does not solve it.

        Args:
            w_m: weight of the manipulation term.
            diag: ``[n]`` ``w_d·D² + λ`` per coordinate.
            js, ds: ``[r,n]`` effector Jacobian and ``[r]`` wanted change.
            jrho: ``[m,n]`` pin Jacobian; band_lo/band_hi: ``[m]`` its ε band.
            lo, hi: ``[n]`` step bounds (limits ∩ trust radius).
        """
        pdata = np.concatenate([2.0 * diag, np.full(self.r, 2.0 * w_m)])
        q = np.concatenate([np.zeros(self.n), -2.0 * w_m * ds])
        adata = self._a_data(js, jrho)
        lower = np.concatenate([np.zeros(self.r), band_lo, lo])
        upper = np.concatenate([np.zeros(self.r), band_hi, hi])
        if self._solver is None:
            nv = self.n + self.r
            pm = sp.csc_matrix((pdata, np.arange(nv), np.arange(nv + 1)), shape=(nv, nv))
            am = sp.csc_matrix((adata, *self._a_pattern), shape=(self.r + self.m + self.n, nv))
            self._solver = osqp.OSQP()
            self._solver.setup(
                pm, q, am, lower, upper,
                verbose=False, eps_abs=self._eps, eps_rel=self._eps,
                max_iter=self._max_iter, polishing=False, warm_starting=True,
            )  # fmt: skip
        else:
            self._solver.update(q=q, l=lower, u=upper, Px=pdata, Ax=adata)
        res = self._solver.solve(raise_error=False)
        if res.info.status not in ("solved", "solved inaccurate") or res.x is None:
            return None
        x = np.asarray(res.x[: self.n], dtype=np.float64)
        return x if np.all(np.isfinite(x)) else None
