"""The tangent-space solver of thesis §4.2 (Eq. 4.10): drag a trajectory, the tangents change, no key is added.

A drag asks that a point on joint ``e`` pass through ``s'`` (and optionally face an
orientation) at time ``t`` inside the keys ``[t_k, t_{k+1}]``. Only that segment's tangents
``θ_{i,k+}``, ``θ_{i,k+1−}`` of the channels ``i ∈ C`` can matter (§4.2.3), so they are the
variables, four per channel (time and value of each). Each iteration linearises (Eq. 4.1–4.2)
``J_s = ∂s/∂c · ∂c/∂θ`` — the first factor is the static IK's analytic Jacobian
(:mod:`engine.ik.jacobian`), the second is analytic too: ``∂c/∂θ^Y`` are the Bézier
weights and ``∂c/∂θ^X`` follows from ``B^X(λ) = t`` by the implicit function theorem —
and solves one QP on the shared core::

    min  w_m‖Δs' − J_s Δθ‖² + w_d‖D (θ' − θ₀)‖² + w_b‖T⁺θ' − T⁻θ'‖² + λ‖Δθ‖²
    s.t. Δρ' − ε ≤ J_ρ Δθ ≤ Δρ' + ε                 (pins and contacts, Eq. 4.11)
         tangent limits (Eq. 4.7–4.9, :mod:`.limits`)

``E_b`` pairs each optimised tangent with the other side of its key (which belongs to the
neighbouring segment and stays fixed), so it is a diagonal term plus a linear one.
``E_d``'s ``Δθ`` is measured from the tangents the drag started from (θ' − θ of Eq. 4.4, θ
the clip before the drag), not from the current iterate: every iteration then minimises the
same energy, and the QP settles E_d and E_b's trade-off exactly in one step. Re-measured
from each iterate, E_d becomes a fixed damping that lets each step close only
``w_b / (w_b + w_d·D²)`` (about half) of E_b's gap along J's null space, and each such
move bends the chain off the target again: unconstrained drags, where the whole chain is
free, then crawled to the tolerance at ~3× per iteration instead of converging in 2–3.
Where a step fails (a contact's linearisation is poor), damping of the step ``μ·w_d‖DΔθ‖²``
is added back, Levenberg–Marquardt style: doubled on a failed step, quartered on a good one,
zero at the first iteration (which is therefore exactly Eq. 4.10). Where the chain is
nearly singular, E_d's pull from θ₀ can hold the point a little short of the target
(w_m is large, not infinite); a step that stops improving moves E_d's reference to the
current tangents, so from there E_d only damps, as in the per-iterate form.
Pins hold a joint point on its trajectory over a frame range, contacts hold it where it
was at the range's first frame; both are sampled at the frames of the range that fall in
the segment, at most ``4·|C_sj|`` of them (§4.2.3). Iterations re-linearise until the
point is within ``tolerance``; a step that does not bring it closer is a strike, and
after ``patience`` strikes the drag is rejected and the clip stays as it was (§4.2.3).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from authoring.keyframe_curves.jacobian import _fk, batch_points
from authoring.keyframe_curves.limits import segment_bounds
from engine import quat
from engine.ik import IKRig
from engine.keyframes import KeyframedClip, bezier_basis, bezier_basis_slope
from engine.qp import LeastSquaresQP

__all__ = ["Drag", "Hold", "CurveSettings", "CurveEdit", "TangentSolver", "curve_rig"]

from engine.arrays import F64 as F


@dataclass(frozen=True)
class Drag:
    """Move ``point`` (local to ``joint``) to ``position`` (and/or turn the joint to ``orientation``) at ``time``."""

    joint: int | str
    time: float
    position: ArrayLike | None = None
    orientation: ArrayLike | None = None
    point: ArrayLike = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Hold:
    """A pin (``contact=False``: keep the trajectory) or a contact (stay at the first frame's place) over frames."""

    joint: int | str
    first: int
    last: int
    contact: bool = False
    point: ArrayLike = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class CurveSettings:
    """Thesis weights (w_m = 100, w_d = w_b = 1, λ = 1e-6, ε = 1e-4) and the stopping rule.

    ``length_unit`` as in :class:`engine.ik.IKSettings`: the weights were tuned in
    centimetres; ``tolerance`` and ``epsilon`` are metres.
    """

    w_m: float = 100.0
    length_unit: float = 0.01
    w_d: float = 1.0
    w_b: float = 1.0
    regularization: float = 1e-6
    tolerance: float = 1e-4
    epsilon: float = 1e-4
    orientation_scale: float = 0.2
    patience: int = 5
    max_iterations: int = 40
    step_radius: float = 0.5
    tangent_radius: float = 0.4
    linked_tangents: bool = True


@dataclass
class CurveEdit:
    """What a drag did: the clip to show, whether the target was met, and diagnostics."""

    clip: KeyframedClip
    reached: bool
    iterations: int
    error: float
    hold_error: float
    variables: int
    segment: int
    closest: KeyframedClip = field(repr=False)
    closest_error: float = 0.0
    closest_hold_error: float = 0.0


def curve_rig(clip: KeyframedClip, limits: IKRig | None = None) -> IKRig:
    """The all-ball rig with root translation whose coordinates are the clip's channels.

    Limits come from ``limits`` (a rig on the same skeleton, e.g. :func:`engine.ik.humanoid_rig`)
    where it has ball joints; elsewhere ±π.
    """
    sk = clip.skeleton
    lim: dict[str, tuple[ArrayLike, ArrayLike]] = {}
    stiff: dict[str, ArrayLike] = {}
    if limits is not None:
        for j, name in enumerate(sk.names):
            cols = np.nonzero((limits.dof_joint == j) & ~limits.dof_translation)[0]
            if cols.size == 3:
                lim[name] = (limits.lower[cols], limits.upper[cols])
            if cols.size:
                stiff[name] = limits.stiffness[cols] if cols.size == 3 else float(limits.stiffness[cols[0]])
    return IKRig.build(sk, limits=lim, stiffness=stiff, root_translation=True)


class _Segment:
    """The variables of one drag: segment, channels, bounds, sample times and hold targets."""

    def __init__(self, solver: TangentSolver, drag: Drag, holds: tuple[Hold, ...]) -> None:
        clip, rig = solver.clip, solver.rig
        sk, curves = clip.skeleton, clip.curves
        t = float(drag.time)
        if clip.loop:
            t = float(curves.times[0] + np.mod(t - curves.times[0], clip.duration))
        self.k = k = int(curves.segment_of(t))
        t0, t1 = float(curves.times[k]), float(curves.times[k + 1])
        self._link(clip, solver.settings.linked_tangents)
        if not t0 < t < t1:
            raise ValueError(f"time {drag.time:.4f} s is on a key: tangents cannot move a key (drag between keys)")
        self.time = t
        self.eff = sk.index(drag.joint) if isinstance(drag.joint, str) else int(drag.joint)
        if drag.position is None and drag.orientation is None:
            raise ValueError("a drag needs a position or an orientation")
        self.eff_point = np.asarray(drag.point, dtype=np.float64).reshape(3)
        self.target = None if drag.position is None else np.asarray(drag.position, dtype=np.float64).reshape(3)
        self.target_rot = None if drag.orientation is None else quat.normalize(np.asarray(drag.orientation, float))
        # §4.2.3 reduction of the channel set C.
        above = rig.ancestors[self.eff][rig.dof_joint] & ~solver.frozen
        active = above.copy()
        kept: list[tuple[Hold, int, NDArray[np.bool_]]] = []
        for h in holds:
            j = sk.index(h.joint) if isinstance(h.joint, str) else int(h.joint)
            cj = rig.ancestors[j][rig.dof_joint] & ~solver.frozen
            if not (cj & active).any():
                continue  # (1) nothing optimised moves it
            if not (cj & ~above).any():
                active &= ~cj  # (2) its channels are all the effector's: freeze them, drop the row
                continue
            kept.append((h, j, cj))
        for _, _, cj in kept:
            active |= cj  # (3) keep the row, optimise its channels too
        self.channels = np.nonzero(active)[0]
        if self.channels.size == 0:
            raise ValueError("every channel above the dragged joint is held by a pin")
        # Samples of each hold: frames of its range strictly inside the segment (§4.2.3 cap).
        fps = clip.fps
        self.hold_joint, self.hold_point, self.hold_time, self.hold_target = [], [], [], []
        for h, j, cj in kept:
            if h.first > h.last:
                raise ValueError(f"hold on {sk.names[j]!r}: first frame after last")
            frames = np.arange(h.first, h.last + 1) / fps
            if clip.loop:
                frames = curves.times[0] + np.mod(frames - curves.times[0], clip.duration)
            seg_of = curves.segment_of(frames)
            strictly = (frames > curves.times[seg_of]) & (frames < curves.times[seg_of + 1])
            inside = frames[strictly & np.isin(seg_of, self.segments)]
            cap = 4 * int(cj.sum())
            if inside.size > cap:
                inside = inside[np.round(np.linspace(0, inside.size - 1, cap)).astype(int)]
            if inside.size == 0:
                continue
            pt = np.asarray(h.point, dtype=np.float64).reshape(3)
            if h.contact:
                start = solver.points(np.array([h.first / fps]), j, pt)[0]
                goal = np.repeat(start[None], inside.size, axis=0)
            else:
                goal = solver.points(inside, j, pt)
            for s, g in zip(inside, goal, strict=True):
                self.hold_joint.append(j)
                self.hold_point.append(pt)
                self.hold_time.append(float(s))
                self.hold_target.append(g)
        self.n_hold = len(self.hold_time)
        self.lo, self.hi = segment_bounds(curves, k, self.channels, rig.lower[self.channels], rig.upper[self.channels])
        self._partner_bounds(clip, rig)

    def _link(self, clip: KeyframedClip, linked: bool) -> None:
        """The neighbouring segments whose tangents are the drag's too (unbroken tangents, thesis §4.2.2).

        An unbroken tangent ``θ_{i,k}`` is one variable for both segments at key ``k``: the
        tangent at the segment's first key is also the in-tangent of the segment before
        (``left``), the one at its last key the out-tangent of the segment after (``right``).
        Their stored handles move by the same change, scaled by the ratio of the key spacings
        (a handle proportional to its spacing stays so), so a curve that was C¹ at a key stays
        C¹ and a drag bends three segments smoothly instead of kinking one at its keys.
        """
        c, k = clip.curves, self.k
        last = c.times.size - 1
        gap = float(c.times[k + 1] - c.times[k])
        left = k - 1 if k > 0 else (last - 1 if clip.loop else None)
        right = k + 1 if k + 1 < last else (0 if clip.loop else None)
        self.left = left if linked and left is not None and left != k else None
        self.right = right if linked and right is not None and right != k else None
        self.s_left = 0.0 if self.left is None else float(c.times[self.left + 1] - c.times[self.left]) / gap
        self.s_right = 0.0 if self.right is None else float(c.times[self.right + 1] - c.times[self.right]) / gap
        self.segments = np.array([j for j in (k, self.left, self.right) if j is not None], dtype=np.int64)

    def _partner_bounds(self, clip: KeyframedClip, rig: IKRig) -> None:
        """Narrow θ's bounds so the linked handles keep Eq. 4.7–4.9 in their own segments too."""
        c, ch, nc = clip.curves, self.channels, self.channels.size
        th0 = self.theta(clip)
        links = []
        if self.left is not None:  # θ blocks X_k, Y_k ↔ the left segment's in-handle (its blocks 2, 3)
            end = self.left + 1
            links.append((self.left, self.s_left, (0, 1), (2, 3), (c.in_x[end, ch], c.in_y[end, ch])))
        if self.right is not None:  # θ blocks X_{k+1}, Y_{k+1} ↔ the right segment's out-handle (its blocks 0, 1)
            links.append((self.right, self.s_right, (2, 3), (0, 1), (c.out_x[self.right, ch], c.out_y[self.right, ch])))
        for seg, scale, mine, theirs, now in links:
            lo_p, hi_p = segment_bounds(c, seg, ch, rig.lower[ch], rig.upper[ch])
            for b, pb, cur in zip(mine, theirs, now, strict=True):
                at, part = slice(b * nc, (b + 1) * nc), slice(pb * nc, (pb + 1) * nc)
                # θ = θ0 + (partner − partner0)/scale; a start already outside stays allowed where it is.
                lo = th0[at] + (lo_p[part] - cur) / scale
                hi = th0[at] + (hi_p[part] - cur) / scale
                self.lo[at] = np.maximum(self.lo[at], np.minimum(lo, th0[at]))
                self.hi[at] = np.minimum(self.hi[at], np.maximum(hi, th0[at]))

    def theta(self, clip: KeyframedClip) -> F:
        """``[4C']`` current ``[X+, Y+, X−, Y−]`` of the segment's channels."""
        c, k, ch = clip.curves, self.k, self.channels
        return np.concatenate([c.out_x[k, ch], c.out_y[k, ch], c.in_x[k + 1, ch], c.in_y[k + 1, ch]])

    def partner(self, clip: KeyframedClip) -> tuple[F, NDArray[np.bool_]]:
        """The other side of each optimised tangent's key (E_b), and which have one."""
        c, k, ch = clip.curves, self.k, self.channels
        last = c.times.size - 1
        has_in = (k > 0 or clip.loop) and self.left is None  # a linked handle moves with θ: nothing to pull towards
        has_out = (k + 1 < last or clip.loop) and self.right is None
        kin = k if k > 0 else last  # a loop's key 0 is its last key one period earlier
        kout = k + 1 if k + 1 < last else 0
        nc = ch.size
        p = np.concatenate([c.in_x[kin, ch], c.in_y[kin, ch], c.out_x[kout, ch], c.out_y[kout, ch]])
        mask = np.concatenate([np.full(2 * nc, has_in), np.full(2 * nc, has_out)])
        return p, mask

    def with_theta(self, clip: KeyframedClip, th: F) -> KeyframedClip:
        c, k, ch = clip.curves, self.k, self.channels
        nc = ch.size
        delta = th - self.theta(clip)
        ox, oy, ix, iy = (np.array(a) for a in (c.out_x, c.out_y, c.in_x, c.in_y))
        ox[k, ch], oy[k, ch], ix[k + 1, ch], iy[k + 1, ch] = th[:nc], th[nc : 2 * nc], th[2 * nc : 3 * nc], th[3 * nc :]
        if self.left is not None:  # the same handle seen from the segment before
            end, gap = self.left + 1, c.times[self.left + 1] - c.times[self.left]
            ix[end, ch] = np.clip(ix[end, ch] + self.s_left * delta[:nc], 0.0, gap)
            iy[end, ch] += self.s_left * delta[nc : 2 * nc]
        if self.right is not None:  # …and from the segment after
            r, gap = self.right, c.times[self.right + 1] - c.times[self.right]
            ox[r, ch] = np.clip(ox[r, ch] + self.s_right * delta[2 * nc : 3 * nc], 0.0, gap)
            oy[r, ch] += self.s_right * delta[3 * nc :]
        return replace(clip, curves=c.with_tangents(ox, oy, ix, iy))


class TangentSolver:
    """Drags on one keyframed clip; QP workspaces are kept per problem shape and warm-started.

    Args:
        clip: the clip being edited (replace :attr:`clip` with each accepted edit's result).
        rig: its channel rig (default :func:`curve_rig` of the clip: ±π limits, unit stiffness).
        frozen: channels no drag may change (e.g. ``range(3)``: the root's translation).
    """

    def __init__(self, clip: KeyframedClip, rig: IKRig | None = None, settings: CurveSettings = CurveSettings(),
                 frozen: ArrayLike = ()) -> None:  # fmt: skip
        self.clip = clip
        self.rig = curve_rig(clip) if rig is None else rig
        if self.rig.num_dofs != clip.curves.num_channels:
            raise ValueError("the rig's coordinates must be the clip's channels (see curve_rig)")
        self.frozen = np.zeros(clip.curves.num_channels, dtype=bool)
        self.frozen[np.asarray(frozen, dtype=np.int64)] = True
        self.settings = settings
        self._qps: dict[tuple[int, int, int], LeastSquaresQP] = {}

    def points(self, times: F, joint: int, point: F, clip: KeyframedClip | None = None) -> F:
        """``[T,3]`` world positions of a joint point at ``times``."""
        wp, wm = _fk(self.rig, (clip or self.clip).coordinates(times))
        return wp[:, joint] + wm[:, joint] @ np.asarray(point, dtype=np.float64)

    def _linearise(self, seg: _Segment, clip: KeyframedClip, times: F, joints: list[int], pts: list[F],
                   rot_joint: int | None) -> tuple[F, F, F | None, F | None]:  # fmt: skip
        """Points ``[T,3]`` and their Jacobians ``[3T, 4C']`` (and the effector's orientation/Jacobian)."""
        curves, ch, rig, _sk = clip.curves, seg.channels, self.rig, self.rig.skeleton
        k = seg.k
        kk, lam_all = curves.parameter(times)
        c_all = curves.evaluate(kk, lam_all)
        lam = lam_all[:, ch]  # [T,C']
        gap = (curves.times[kk + 1] - curves.times[kk])[:, None]  # each sample in its own segment
        a, b = curves.out_x[kk][:, ch], curves.in_x[kk + 1][:, ch]
        ya, yb = curves.out_y[kk][:, ch], curves.in_y[kk + 1][:, ch]
        v0, v1 = curves.values[kk][:, ch], curves.values[kk + 1][:, ch]
        h0, tp, h1, tm = bezier_basis(lam)
        d0, dtp, d1, dtm = bezier_basis_slope(lam)
        dx = dtp * a + d1 * gap + dtm * b
        dy = d0 * v0 + dtp * ya + d1 * v1 + dtm * yb
        slope = dy / np.where(np.abs(dx) > 1e-12, dx, 1e-12)
        main = (kk == k)[:, None]
        left = (kk == (-1 if seg.left is None else seg.left))[
            :, None
        ] * seg.s_left  # θ_k as the left segment's in-handle
        right = (kk == (-1 if seg.right is None else seg.right))[
            :, None
        ] * seg.s_right  # θ_{k+1} as the right one's out
        dc = np.concatenate([(-slope * tp) * main + (-slope * tm) * left, tp * main + tm * left,
                             (-slope * tm) * main + (-slope * tp) * right, tm * main + tp * right], axis=1)  # fmt: skip
        nc = ch.size
        pos, js, rot_now, jo = batch_points(
            rig, c_all, np.asarray(joints, dtype=np.int64), np.asarray(pts), ch, rot_joint
        )
        jac = (np.tile(js, (1, 1, 4)) * dc[:, None, :]).reshape(3 * len(times), 4 * nc)
        rot_jac = None if jo is None else np.tile(jo, (1, 4)) * dc[0][None]
        return pos, jac, rot_now, rot_jac

    def drag(self, drag: Drag, holds: tuple[Hold, ...] | list[Hold] = ()) -> CurveEdit:
        """Solve one drag from :attr:`clip` (which is left unchanged; use the result's ``clip``)."""
        st = self.settings
        seg = _Segment(self, drag, tuple(holds))
        clip = self.clip
        nc = seg.channels.size
        n = 4 * nc
        times = np.array([seg.time, *seg.hold_time])
        joints = [seg.eff, *seg.hold_joint]
        pts = [seg.eff_point, *seg.hold_point]
        rho_goal = np.array(seg.hold_target).reshape(-1)
        stiff = self.rig.stiffness[seg.channels]
        gap = float(clip.curves.times[seg.k + 1] - clip.curves.times[seg.k])
        # D per tangent component: a time component is measured in key spacings, so moving
        # it by the whole spacing resists like turning a joint by a radian. (In seconds it
        # would be nearly free, and the solver would lean on timing, the most non-linear part.)
        stiff_x = stiff / gap
        d_d = st.w_d * np.concatenate([stiff_x, stiff, stiff_x, stiff]) ** 2
        d = d_d + st.regularization
        start = seg.theta(clip)  # E_d's reference
        partner, has_partner = seg.partner(clip)
        d_b = np.where(has_partner, st.w_b, 0.0)
        w_m = st.w_m / st.length_unit**2
        rows = (3 if seg.target is not None else 0) + (3 if seg.target_rot is not None else 0)
        key = (n, rows, 3 * seg.n_hold)
        qp = self._qps.get(key)
        if qp is None:
            qp = self._qps[key] = LeastSquaresQP(n, rows, 3 * seg.n_hold)
        # Eq. 4.11's band is per component; ε/√3 per component keeps each held point within ε
        # in distance, with half of it left as margin for the linearisation error.
        band = 0.5 * st.epsilon / np.sqrt(3.0)
        rot_joint = seg.eff if seg.target_rot is not None else None

        def residuals(pos: F, rot_now: F | None) -> tuple[F, F]:
            ds = []
            if seg.target is not None:
                ds.append(seg.target - pos[0])
            if seg.target_rot is not None and rot_now is not None:
                ds.append(st.orientation_scale * quat.log(quat.mul(seg.target_rot, quat.conjugate(rot_now))))
            drho = rho_goal - pos[1:].reshape(-1)
            return np.concatenate(ds), drho

        def error_of(ds: F) -> float:
            return float(np.max(np.linalg.norm(ds.reshape(-1, 3), axis=-1), initial=0.0))

        def hold_error(drho: F) -> float:
            return float(np.max(np.linalg.norm(drho.reshape(-1, 3), axis=-1), initial=0.0))

        def merit(ds: F, drho: F) -> float:
            excess = np.maximum(np.linalg.norm(drho.reshape(-1, 3), axis=-1) - st.epsilon, 0.0)
            return float(np.linalg.norm(ds) + np.linalg.norm(excess))

        def done_of(ds: F, drho: F) -> bool:
            return error_of(ds) < st.tolerance and hold_error(drho) <= st.epsilon

        pos, jac, rot_now, rot_jac = self._linearise(seg, clip, times, joints, pts, rot_joint)
        ds, drho = residuals(pos, rot_now)
        cur = merit(ds, drho)
        best, strikes, it = cur, 0, 0
        # The closest solution kept when the target is out of reach (§4.4): the nearest iterate whose holds are within ε.
        best_clip, best_err, best_hold = clip, error_of(ds), hold_error(drho)
        radius, box_r = st.step_radius, st.tangent_radius
        mu = 0.0  # extra damping of the step, Levenberg–Marquardt style: grows when a step fails
        done = done_of(ds, drho)
        while not done and it < st.max_iterations and strikes < st.patience:
            it += 1
            th = seg.theta(clip)
            g_rows = []
            if seg.target is not None:
                g_rows.append(jac[:3])
            if rot_jac is not None:
                g_rows.append(st.orientation_scale * rot_jac)
            g = np.vstack(g_rows)
            want = ds.reshape(-1, 3)
            norms = np.linalg.norm(want, axis=-1, keepdims=True)
            want = want * np.minimum(1.0, radius / np.maximum(norms, 1e-12))
            # Trust region on the tangents too: value components by ``box`` (radians or metres),
            # time components by that fraction of the key spacing.
            box = np.concatenate([np.full(nc, box_r * gap), np.full(nc, box_r), np.full(nc, box_r * gap),
                                  np.full(nc, box_r)])  # fmt: skip
            lo, hi = np.maximum(seg.lo - th, -box), np.minimum(seg.hi - th, box)
            bad = lo > hi
            lo[bad], hi[bad] = np.clip(0.0, lo, hi)[bad], np.clip(0.0, lo, hi)[bad]
            linear = 2.0 * d_b * (th - partner) + 2.0 * d_d * (th - start)
            res = qp.solve(d + d_b + mu * d_d, g, want.reshape(-1), w_m, lo, hi, jac[3:], drho - band, drho + band,
                           linear=linear)  # fmt: skip
            if res.x is None:
                strikes += 1
                radius, box_r, mu = 0.5 * radius, 0.5 * box_r, max(2.0 * mu, 1.0)
                continue
            trial = seg.with_theta(clip, np.clip(th + res.x, seg.lo, seg.hi))
            t_pos, t_jac, t_rot, t_rjac = self._linearise(seg, trial, times, joints, pts, rot_joint)
            t_ds, t_drho = residuals(t_pos, t_rot)
            t_merit = merit(t_ds, t_drho)
            if t_merit < cur or done_of(t_ds, t_drho):
                clip, pos, jac, rot_now, rot_jac, ds, drho, cur = (
                    trial,
                    t_pos,
                    t_jac,
                    t_rot,
                    t_rjac,
                    t_ds,
                    t_drho,
                    t_merit,
                )
                radius = min(2.0 * radius, 4.0 * st.step_radius)
                box_r = min(1.5 * box_r, 2.5 * st.tangent_radius)
                mu *= 0.25
            else:
                radius, box_r, mu = 0.5 * radius, 0.5 * box_r, max(2.0 * mu, 1.0)
            done = done_of(ds, drho)
            if hold_error(drho) <= st.epsilon and error_of(ds) < best_err:
                best_clip, best_err, best_hold = clip, error_of(ds), hold_error(drho)
            if done or cur < best * (1.0 - 1e-3):
                best, strikes = cur, 0
            else:
                strikes += 1
                start = seg.theta(clip)  # stalled: E_d's pull may be what holds the point short
        return CurveEdit(clip=clip if done else self.clip, reached=done, iterations=it, error=error_of(ds),
                         hold_error=hold_error(drho), variables=n, segment=seg.k, closest=best_clip,
                         closest_error=best_err, closest_hold_error=best_hold)  # fmt: skip
