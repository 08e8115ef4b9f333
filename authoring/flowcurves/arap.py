"""As-rigid-as-possible deformation of the grids (Eq. 3.12), with a prefactored sparse system.

The energy is the classic local/global ARAP of triangle meshes: every triangle keeps a
best-fitting rotation ``R_t`` of its rest edges, and
``E = Σ_t Σ_(i,j)∈t ‖(x_i − x_j) − R_t (u_i − u_j)‖²``. The global step is one linear
system whose matrix does not depend on the rotations, so it is factorised once per set
of constraints (``scipy.sparse.linalg.splu``) and every iteration — and every move of a
dragged stroke or centre-point with the same correspondence — costs two triangular solves.

Constraints, as §3.5.3 asks, are hard where they keep the layout: a row ``C x = d`` for a
contact with the fixed ground, ``C_a x − C_b x = 0`` for two objects that touch (both
grids carry the contact point, so it moves with both and they keep touching). They are
enforced exactly through a KKT system. The shape constraints (SEcurve samples onto the
flow curve) are soft, weight :data:`W_SHAPE`, where Eq. 3.12 makes them hard. Why, measured
(``bench flow``'s ``flow_shape_residual_p90_px``; the snowman tree of the tests with its
``bend_stroke``): the samples are 2 px apart and the grid's vertices 15 px, so no grid meets
them all — made hard (weight 10⁵ and up: the residual stops falling there) they still miss by
0.11 px (90th percentile; max 0.26 px) on the snowman tree and 0.02 px on the crystal tree,
and the grid pays for it with twice the distortion energy (ARAP energy 43,000 against
20,000); at 50 they miss by 1.7 px (max 5.6 px) and 0.15 px. Several flow curves and contacts
may also ask for incompatible positions, where hard rows have no solution at all and a soft
term gives the closest rigid-looking answer. A tiny pull to the rest pose (``EPS``)
keeps a grid island without any constraint where it was instead of making the matrix
singular.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

__all__ = ["ArapSystem", "arap_energy", "laplacian", "W_SHAPE", "EPS"]

from engine.arrays import F64 as F
from engine.arrays import I64 as I

W_SHAPE = 50.0
#: Pull to the rest pose that keeps unconstrained islands in place (see the module docstring).
EPS = 1e-6
#: Regularisation of the constraint block of the KKT system (see ``ArapSystem``).
DELTA = 1e-9
_EDGES = ((0, 1), (1, 2), (2, 0))


def laplacian(n: int, triangles: I) -> sp.csr_matrix:
    """Uniform-weight Laplacian summed over every triangle's three edges."""
    i = np.concatenate([triangles[:, a] for a, _ in _EDGES])
    j = np.concatenate([triangles[:, b] for _, b in _EDGES])
    one = np.ones(len(i))
    w = sp.coo_matrix((one, (i, j)), shape=(n, n))
    w = w + w.T
    return (sp.diags(np.asarray(w.sum(axis=1)).ravel()) - w).tocsr()


def _rest_edges(rest: F, triangles: I) -> F:
    return np.stack([rest[triangles[:, a]] - rest[triangles[:, b]] for a, b in _EDGES], axis=1)


def _rotations(rest_edges: F, x: F, triangles: I) -> F:
    """Best rotation per triangle ``[T, 2, 2]`` (2D polar decomposition in closed form)."""
    e = np.stack([x[triangles[:, a]] - x[triangles[:, b]] for a, b in _EDGES], axis=1)
    m = np.einsum("tki,tkj->tij", e, rest_edges)  # Σ x_e u_eᵀ
    ang = np.arctan2(m[:, 1, 0] - m[:, 0, 1], m[:, 0, 0] + m[:, 1, 1])
    c, s = np.cos(ang), np.sin(ang)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], axis=1)


def arap_energy(rest: F, triangles: I, x: F) -> float:
    """Eq. 3.12's shape energy of a deformed grid (rotations fitted per triangle)."""
    u = _rest_edges(rest, triangles)
    r = _rotations(u, x, triangles)
    e = np.stack([x[triangles[:, a]] - x[triangles[:, b]] for a, b in _EDGES], axis=1)
    return float(np.sum((e - np.einsum("tij,tkj->tki", r, u)) ** 2))


class ArapSystem:
    """The ARAP problem of a set of grids (stacked) under fixed constraint rows.

    Args:
        rest: ``[V, 2]`` rest vertices of every grid, stacked.
        triangles: ``[T, 3]`` triangles into ``rest``.
        hard: ``[H, V]`` rows kept exactly (contacts).
        soft: ``[S, V]`` rows pulled to their targets with ``weight`` (SEcurve samples).
    """

    def __init__(self, rest: F, triangles: I, hard: sp.spmatrix, soft: sp.spmatrix, weight: float = W_SHAPE) -> None:
        self.rest, self.triangles, self.weight = np.asarray(rest, dtype=np.float64), triangles, weight
        n = len(self.rest)
        self.hard, self.soft = (
            sp.csr_matrix(hard, shape=(hard.shape[0], n)),
            sp.csr_matrix(soft, shape=(soft.shape[0], n)),
        )
        self.rest_edges = _rest_edges(self.rest, triangles)
        a = laplacian(n, triangles) + weight * (self.soft.T @ self.soft) + EPS * sp.identity(n)
        m = self.hard.shape[0]
        # -δ on the constraint block: two contacts that say the same thing (a cycle of touching
        # objects) would make the KKT matrix singular; δ makes them agree to ~δ·λ instead.
        self.matrix = sp.bmat([[a, self.hard.T], [self.hard, -DELTA * sp.identity(m) if m else None]], format="csc")
        self.lu = splu(self.matrix)
        # Flat edge arrays (edge k of every triangle, k = 0, 1, 2) for the vectorised local step.
        self._ei = np.concatenate([triangles[:, a] for a, _ in _EDGES])
        self._ej = np.concatenate([triangles[:, b] for _, b in _EDGES])
        self._u = np.concatenate([self.rest_edges[:, k] for k in range(3)])

    def _rotated_edges(self, x: F) -> F:
        """The local step: Σ over each vertex's edges of the best-fit rotated rest edges, ``[V, 2]``."""
        n, t = len(self.rest), len(self.triangles)
        e = x[self._ei] - x[self._ej]
        u = self._u
        # per triangle 2x2 covariance Σ_k e_k u_kᵀ, summed over its three edges (rows k·T … (k+1)·T)
        m00 = (e[:, 0] * u[:, 0]).reshape(3, t).sum(0)
        m01 = (e[:, 0] * u[:, 1]).reshape(3, t).sum(0)
        m10 = (e[:, 1] * u[:, 0]).reshape(3, t).sum(0)
        m11 = (e[:, 1] * u[:, 1]).reshape(3, t).sum(0)
        ang = np.arctan2(m10 - m01, m00 + m11)
        c, s = np.tile(np.cos(ang), 3), np.tile(np.sin(ang), 3)
        rx, ry = c * u[:, 0] - s * u[:, 1], s * u[:, 0] + c * u[:, 1]
        return np.c_[
            np.bincount(self._ei, rx, n) - np.bincount(self._ej, rx, n),
            np.bincount(self._ei, ry, n) - np.bincount(self._ej, ry, n),
        ]

    def solve(
        self, hard_targets: F, soft_targets: F, iterations: int = 10, x0: F | None = None, dense: bool = False
    ) -> F:
        """Local/global iterations from ``x0`` (the rest pose by default); ``dense`` is the baseline
        that solves the same KKT system with a dense LU every iteration."""
        n = len(self.rest)
        hard_targets = np.asarray(hard_targets, dtype=np.float64).reshape(-1, 2)
        soft_targets = np.asarray(soft_targets, dtype=np.float64).reshape(-1, 2)
        x = self.rest.copy() if x0 is None else np.array(x0, dtype=np.float64)
        full = self.matrix.toarray() if dense else None
        rhs = np.empty((n + len(hard_targets), 2))
        rhs[n:] = hard_targets
        fixed = self.weight * (self.soft.T @ soft_targets) + EPS * self.rest  # the same every iteration
        for _ in range(iterations):
            rhs[:n] = self._rotated_edges(x) + fixed
            sol = np.linalg.solve(full, rhs) if full is not None else self.lu.solve(rhs)
            x = sol[:n]
        return x

    def linear_solve(self, hard_targets: F, soft_targets: F) -> F:
        """The same constraints met by plain Laplacian editing (every rotation the identity):
        the non-rigid answer ARAP improves on, kept as a reference for tests."""
        n = len(self.rest)
        rhs = np.vstack(
            [
                laplacian(n, self.triangles) @ self.rest + self.weight * (self.soft.T @ soft_targets) + EPS * self.rest,
                np.asarray(hard_targets, dtype=np.float64).reshape(-1, 2),
            ]
        )
        return self.lu.solve(rhs)[:n]

    def energy(self, x: F) -> float:
        """ARAP energy of ``x``."""
        return arap_energy(self.rest, self.triangles, x)
