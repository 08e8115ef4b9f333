"""One linearised IK step as a dense QP on the shared core (:mod:`engine.qp`).

Each iteration of the optimisation IK solves (thesis Eq. 4.13 with the ε band of
Eq. 4.11 and the regulariser λ of §4.2.3)::

    min_Δc  w_m‖Δs − J_s Δc‖² + w_d‖D Δc‖² + λ‖Δc‖²
    s.t.    Δρ' − ε ≤ J_ρ Δc ≤ Δρ' + ε          (pins)
            max(u − c, −r) ≤ Δc ≤ min(v − c, r)    (limits, and a trust radius r)

It is a least-squares QP with a diagonal damping, the shape
:class:`engine.qp.LeastSquaresQP` takes (it lifts ``J_s Δc`` into auxiliary variables so
the solver's Hessian is diagonal); one workspace per solve is set up once and
warm-started from the previous step's active set. (The OSQP version this replaces needed ~250 ADMM
iterations per step at 168 coordinates, and occasionally hit its 10,000 cap.)
"""

from __future__ import annotations

from engine.qp import LeastSquaresQP

__all__ = ["StepQP"]

from engine.arrays import F64 as F


class StepQP:
    """A reusable QP of ``n`` coordinates, ``r`` effector rows and ``m`` pin rows."""

    def __init__(self, n: int, r: int, m: int, *, iter_limit: int = 2000) -> None:
        self.n, self.r, self.m = n, r, m
        self._qp = LeastSquaresQP(n, r, m, iter_limit=iter_limit)

    def solve(self, w_m: float, diag: F, js: F, ds: F, jrho: F, band_lo: F, band_hi: F, lo: F, hi: F) -> F | None:
        """The step ``Δc`` of the QP above, or ``None`` when the core reports no solution.

        Args:
            w_m: weight of the manipulation term.
            diag: ``[n]`` ``w_d·D² + λ`` per coordinate.
            js, ds: ``[r,n]`` effector Jacobian and ``[r]`` wanted change.
            jrho: ``[m,n]`` pin Jacobian; band_lo/band_hi: ``[m]`` its ε band.
            lo, hi: ``[n]`` step bounds (limits ∩ trust radius).
        """
        return self._qp.solve(diag, js, ds, w_m, lo, hi, jrho, band_lo, band_hi).x
