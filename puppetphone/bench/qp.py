"""Which QP solver the core uses: DAQP, ProxSuite, PIQP and OSQP on the project's real QPs.

The problems are recorded, not synthetic: every step QP of the static IK on the bench's
168-dof tentacle with 3 pins (``bench.ik``, 20 targets), and the MoCurves time warp at
120 keypoints over a 20-move drag. Each solver gets each problem in the form that suits it
best and the same warm-start chance: one workspace per IK solve (as the solver keeps it)
and per drag, updated between QPs. Figures are microseconds per QP (median of 5 passes
over all problems; one pass for the peers, which are much slower on the IK problems) with
DAQP — the core's choice — as the baseline, plus the largest
difference of each solver's answer from DAQP's.

Forms: ``dense`` hands the solver ``H = 2(w J_sᵀJ_s + D)`` directly; ``lifted`` is the
core's :class:`engine.qp.LeastSquaresQP` form (``y = J_s x`` as extra variables, diagonal H).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from typing import Any
from unittest import mock

import numpy as np

from puppetphone.bench.figures import Figure

__all__ = ["run"]

Problem = tuple[int, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _ik_problems() -> list[Problem]:
    """``(group, H, f, A, blo, bhi, lo, hi)`` of every IK step QP (dense form)."""
    import engine.ik.qp as ikqp
    from engine import quat
    from engine.ik import Effector, IKRig, Pin, solve_ik
    from puppetphone.bench.ik import LIMIT, TIP, chain_skeleton, chain_targets, pin_joints

    rec: list[Problem] = []
    orig = ikqp.StepQP.solve

    def spy(self: Any, w: float, diag: np.ndarray, js: np.ndarray, ds: np.ndarray, jr: np.ndarray, blo: np.ndarray,
            bhi: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> Any:  # fmt: skip
        h = 2.0 * w * (js.T @ js)
        h[np.diag_indices(len(diag))] += 2.0 * diag
        rec.append((id(self), h, -2.0 * w * (js.T @ ds), jr.copy(), blo.copy(), bhi.copy(), lo.copy(), hi.copy()))
        return orig(self, w, diag, js, ds, jr, blo, bhi, lo, hi)

    sk = chain_skeleton(56)
    rig = IKRig.build(sk, limits=dict.fromkeys(sk.names, (-LIMIT, LIMIT)))
    pj = pin_joints(56, 3)
    with mock.patch.object(ikqp.StepQP, "solve", spy):
        for c0, target in chain_targets(rig, pj, 20, seed=1683):
            root, rot = rig.to_pose(c0, quat.identity(56), np.zeros(3))
            solve_ik(rig, root, rot, [Effector(55, target, point=TIP)], [Pin(j) for j in pj])
    return rec


def _warp_problems() -> list[Problem]:
    from authoring.mocurves.timewarp import TimeWarp
    from puppetphone.bench.mocurves import _drag

    n = 120
    w = TimeWarp(n, 1.0)
    out: list[Problem] = []
    for step in range(20):
        cons = _drag(n, step)
        c = np.zeros(n + 1, dtype=bool)
        tgt = np.zeros(n + 1)
        for k, v in cons.items():
            c[k], tgt[k] = True, v
        h = w._h_base.copy()
        h[np.diag_indices(n + 1)] += 2.0 * w.w_strong * c
        f = w._f_base - 2.0 * w.w_strong * tgt * c
        inf = np.full(n + 1, np.inf)
        out.append((0, h, f, w._a, np.zeros(n), np.full(n, np.inf), -inf, inf))
    return out


def _daqp(probs: list[Problem]) -> list[np.ndarray | None]:
    from engine.qp import DenseQP

    out: list[np.ndarray | None] = []
    cur, qp = None, None
    for key, h, f, a, blo, bhi, lo, hi in probs:
        if key != cur:
            qp, cur = DenseQP(len(f), a.shape[0]), key
        assert qp is not None
        out.append(qp.solve(h, f, lo, hi, a, blo, bhi).x)
    return out


def _proxsuite(probs: list[Problem]) -> list[np.ndarray]:
    import proxsuite

    out: list[np.ndarray] = []
    cur = None
    qp: Any = None  # the solver's workspace (an untyped library)
    for key, h, f, a, blo, bhi, lo, hi in probs:
        n, m = len(f), a.shape[0]
        big = 1e20
        args = (
            h,
            f,
            None,
            None,
            a,
            np.maximum(blo, -big),
            np.minimum(bhi, big),
            np.maximum(lo, -big),
            np.minimum(hi, big),
        )
        if key != cur:
            qp, cur = proxsuite.proxqp.dense.QP(n, 0, m, True), key
            qp.settings.eps_abs = 1e-6
            qp.settings.verbose = False
            qp.init(*args)
        else:
            qp.update(*args)
        qp.solve()
        out.append(np.array(qp.results.x))
    return out


def _piqp(probs: list[Problem]) -> list[np.ndarray]:
    import piqp

    out: list[np.ndarray] = []
    cur = None
    s: Any = None  # the solver's workspace (an untyped library)
    for key, h, f, a, blo, bhi, lo, hi in probs:
        if key != cur:
            s, cur = piqp.DenseSolver(), key
            s.settings.verbose = False
            s.setup(h, f, None, None, a, blo, bhi, lo, hi)
        else:
            s.update(P=h, c=f, G=a, h_l=blo, h_u=bhi, x_l=lo, x_u=hi)
        s.solve()
        out.append(np.array(s.result.x))
    return out


def _osqp(probs: list[Problem]) -> list[np.ndarray]:
    import osqp
    import scipy.sparse as sp

    out: list[np.ndarray] = []
    cur = None
    s: Any = None  # the solver's workspace (an untyped library)
    for key, h, f, a, blo, bhi, lo, hi in probs:
        n = len(f)
        am = sp.csc_matrix(np.vstack([a, np.eye(n)]))
        low, up = np.r_[blo, lo], np.r_[bhi, hi]
        if key != cur:
            s, cur = osqp.OSQP(), key
            s.setup(sp.csc_matrix(np.triu(h)), f, am, low, up, verbose=False, eps_abs=1e-6, eps_rel=1e-6,
                    max_iter=10000, polishing=False, warm_starting=True)  # the settings the IK used  # fmt: skip
        else:
            s.update(Px=sp.csc_matrix(np.triu(h)).data, q=f, Ax=am.data, l=low, u=up)
        out.append(np.asarray(s.solve(raise_error=False).x))
    return out


def _time(fn: Callable[[list[Problem]], Sequence[np.ndarray | None]], probs: list[Problem],
          passes: int = 5) -> tuple[float, Sequence[np.ndarray | None]]:  # fmt: skip
    ts = []
    xs: Sequence[np.ndarray | None] = []
    for _ in range(passes):
        t0 = time.process_time()
        xs = fn(probs)
        ts.append(time.process_time() - t0)
    return float(np.median(ts)) / len(probs) * 1e6, xs


def run() -> list[Figure]:
    """Per-QP microseconds of each installed solver on the recorded problems, DAQP as the baseline."""
    figures = []
    for tag, probs in (("ik168_3pins", _ik_problems()), ("timewarp120", _warp_problems())):
        base_us, ref = _time(_daqp, probs)
        figures.append(Figure("qp", f"qp_us_{tag}_daqp", base_us, "us"))
        for name, fn in (("proxsuite", _proxsuite), ("piqp", _piqp), ("osqp", _osqp)):
            try:
                us, xs = _time(fn, probs, passes=1)  # the slower peers: one pass
            except ImportError as exc:
                print(f"qp: {name} skipped ({exc.name} not installed)", file=sys.stderr)
                continue
            diff = max(float(np.max(np.abs(x - r))) if x is not None and r is not None else np.inf
                       for x, r in zip(xs, ref, strict=True))  # fmt: skip
            figures.append(Figure("qp", f"qp_us_{tag}_{name}", us, "us", "daqp, same problems", base_us))
            figures.append(Figure("qp", f"qp_maxdiff_{tag}_{name}", diff, "", "daqp answer", None))
    figures.append(_lifted())
    return figures


def _lifted() -> Figure:
    """The IK step QPs in the core's lifted form (what :mod:`engine.ik.qp` runs) vs the dense form."""
    import engine.ik.qp as ikqp
    from engine.qp import LeastSquaresQP

    raw: list[tuple] = []
    orig = ikqp.StepQP.solve

    def spy(self: Any, *args: Any) -> Any:
        raw.append((id(self),) + tuple(np.copy(a) if isinstance(a, np.ndarray) else a for a in args))
        return orig(self, *args)

    with mock.patch.object(ikqp.StepQP, "solve", spy):
        dense = _ik_problems()

    def lifted(_: list[Problem]) -> list[np.ndarray | None]:
        out: list[np.ndarray | None] = []
        cur, qp = None, None
        for key, w, diag, js, ds, jr, blo, bhi, lo, hi in raw:
            if key != cur:
                qp, cur = LeastSquaresQP(len(diag), len(ds), jr.shape[0]), key
            assert qp is not None
            out.append(qp.solve(diag, js, ds, w, lo, hi, jr, blo, bhi).x)
        return out

    us, _ = _time(lifted, dense)
    dense_us, _ = _time(_daqp, dense)
    return Figure("qp", "qp_us_ik168_3pins_daqp_lifted", us, "us", "daqp, dense form", dense_us)
