"""Principal curves through an object's screen-space samples (§3.3.1, Eq. 3.1).

The curve starts as the principal axis of the samples (largest eigenvector of their
covariance), as long as the samples' extent along it. Each iteration finds every
sample's closest curve parameter ``s_i*`` and then solves, in closed form (the curve is
linear in its Hermite degrees of freedom),

    c_{k+1} = argmin  w1 Σ_i ‖x_i − c(s_i*)‖² + w2 ∫ ‖c'(s) − c_k'(s)‖² ds,

the second term penalising a change of shape from the last curve (not of position), so
a lopsided shape such as a tree does not pull the curve into a spurious bend at once.
The thesis uses w2 = 1000 w1; it is silent on the discretisation — we sum the data term
over the samples and take the integral as the mean over 32 equally spaced points — and on
the number of control points (we use 4).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from authoring.flowcurves.hermite import Hermite, basis

__all__ = ["principal_curve", "W1", "W2", "CONTROL_POINTS"]

W1, W2 = 1.0, 1000.0
CONTROL_POINTS = 4
_DENSE = 128
_REG = 32


def principal_curve(
    samples: ArrayLike, n: int = CONTROL_POINTS, max_iterations: int = 400, tolerance: float = 0.02
) -> Hermite:
    """Eq. 3.1 iterated until no control point moves by more than ``tolerance`` pixels.

    With w2 = 1000 w1 a step moves the shape ~1 % of the way, so on a bent band this
    takes hundreds of (sub-millisecond) iterations (capped at 400, ~98 % of the way); samples
    are thinned to 400.
    """
    x = np.asarray(samples, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 2 or len(x) < 3:
        raise ValueError("a principal curve needs at least three 2D samples")
    if len(x) > 400:
        x = x[np.linspace(0, len(x) - 1, 400).astype(np.int64)]
    mean = x.mean(axis=0)
    cov = np.cov((x - mean).T)
    axis = np.linalg.eigh(cov)[1][:, -1]
    if axis[1] > 0 or (axis[1] == 0 and axis[0] < 0):
        axis = -axis  # a fixed orientation: upwards on screen (then rightwards), for repeatable curves
    proj = (x - mean) @ axis
    curve = Hermite.line(mean + proj.min() * axis, mean + proj.max() * axis, n)
    sreg = np.linspace(0.0, 1.0, _REG)
    d1 = basis(sreg, n, order=1)
    reg = W2 / _REG * (d1.T @ d1)  # the integral's normal matrix, the same every iteration
    dense = basis(np.linspace(0.0, 1.0, _DENSE), n)  # closest points are looked up on these samples
    for _ in range(max_iterations):
        p = dense @ curve.q
        nearest = np.argmin(((x[:, None, :] - p[None]) ** 2).sum(axis=-1), axis=1)
        a = dense[nearest]
        q = np.linalg.solve(W1 * (a.T @ a) + reg + 1e-9 * np.eye(2 * n), W1 * (a.T @ x) + reg @ curve.q)
        moved = float(np.abs(q[:n] - curve.q[:n]).max())
        curve = Hermite(q)
        if moved < tolerance:
            break
    return curve
