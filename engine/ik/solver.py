"""The optimisation IK of thesis §4.2.5: any joint is an effector, pins stay put, limits hold.

The static case of the thesis' tangent-space solver (Eq. 4.13) optimises the rig's
attributes ``c`` directly. Each iteration linearises the effector states ``s(c)``
and the pinned states ``ρ(c)`` with analytic Jacobians, solves one QP
(:class:`engine.ik.qp.StepQP`), applies the step and re-linearises, until every
effector is within ``tolerance`` (§4.2.3's stopping rule). A step that does not
bring the effectors closer counts as non-improving; after ``patience`` (5, as in the
thesis) of them in a row the target is *rejected*: the result reports it
unreachable and, like the thesis, keeps the input configuration (the closest pose
found is still returned for callers that prefer it).

Two practical additions, both standard for Gauss-Newton-type IK: the step is
bounded by a trust radius that grows after good steps and shrinks after bad ones
(a bad step is not applied), and the coordinate set is reduced as in §4.2.3 — only
the attributes above an effector are optimised, plus those above any pin that
shares them; pins that no optimised attribute can move are dropped.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import quat
from engine.ik._fk import fk_matrices
from engine.ik.jacobian import dof_axes, orientation_jacobian, point_jacobian
from engine.ik.qp import StepQP
from engine.ik.rig import IKRig

__all__ = ["Effector", "Pin", "IKSettings", "IKResult", "solve_ik"]

from engine.arrays import F64 as F


@dataclass(frozen=True)
class Effector:
    """A point on any joint (``point`` in its local frame) and where it should go.

    ``position`` is a world target; ``orientation`` an optional world quaternion for
    the joint's frame. At least one must be given.
    """

    joint: int | str
    position: ArrayLike | None = None
    orientation: ArrayLike | None = None
    point: ArrayLike = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Pin:
    """A point that must stay where it is (within ``ε``), optionally with its joint's orientation."""

    joint: int | str
    point: ArrayLike = (0.0, 0.0, 0.0)
    orientation: bool = False


@dataclass(frozen=True)
class IKSettings:
    """Weights and tolerances; defaults are the thesis' (w_m = 100, w_d = 1, λ = 1e-6, ε = 1e-4).

    ``length_unit`` is the unit positions are measured in inside ``E_m``: the thesis'
    weights were tuned in Maya scenes measured in centimetres, so with the default
    (0.01 m) ``w_m = 100`` and ``w_d = 1`` balance a centimetre of miss against a
    radian of change as they did there. ``tolerance`` and ``pin_epsilon`` are metres.
    """

    w_m: float = 100.0
    length_unit: float = 0.01
    w_d: float = 1.0
    regularization: float = 1e-6
    tolerance: float = 1e-4
    pin_epsilon: float = 1e-4
    orientation_scale: float = 0.2
    patience: int = 5
    max_iterations: int = 60
    trust_radius: float = 0.4
    max_trust_radius: float = 1.0


@dataclass
class IKResult:
    """What a solve did: the pose to use, whether the target was reached, and diagnostics."""

    root: F
    rotations: F
    reached: bool
    iterations: int
    error: float
    pin_error: float
    closest_root: F = field(repr=False)
    closest_rotations: F = field(repr=False)
    coordinates: F = field(repr=False)


class _Problem:
    """Effector and pin data resolved to joint indices and local points."""

    def __init__(self, rig: IKRig, effectors: tuple[Effector, ...], pins: tuple[Pin, ...]) -> None:
        sk = rig.skeleton
        if not effectors:
            raise ValueError("solve_ik needs at least one effector")
        idx = [e.joint if isinstance(e.joint, int) else sk.index(e.joint) for e in effectors]
        for e, j in zip(effectors, idx, strict=True):
            if not 0 <= j < sk.num_joints:
                raise ValueError(f"effector joint {j} out of range")
            if e.position is None and e.orientation is None:
                raise ValueError(f"effector on {sk.names[j]!r} has neither a position nor an orientation")
        self.pos_frames = np.array([j for e, j in zip(effectors, idx, strict=True) if e.position is not None], np.int64)
        self.pos_local = np.array([e.point for e in effectors if e.position is not None], float).reshape(-1, 3)
        self.pos_target = np.array([e.position for e in effectors if e.position is not None], float).reshape(-1, 3)
        with_rot = [j for e, j in zip(effectors, idx, strict=True) if e.orientation is not None]
        self.rot_frames = np.array(with_rot, np.int64)
        tq = [quat.normalize(e.orientation) for e in effectors if e.orientation is not None]
        self.rot_target = np.array(tq, float).reshape(-1, 4)
        if not (np.isfinite(self.pos_target).all() and np.isfinite(self.rot_target).all()):
            raise ValueError("effector targets must be finite")
        # §4.2.3 reduction: attributes above the effectors, plus pins sharing them.
        eff_frames = np.array(idx, np.int64)
        active = rig.ancestors[eff_frames][:, rig.dof_joint].any(axis=0)
        pin_idx = [p.joint if isinstance(p.joint, int) else sk.index(p.joint) for p in pins]
        kept = [p for p, j in zip(pins, pin_idx, strict=True) if (rig.ancestors[j][rig.dof_joint] & active).any()]
        kept_idx = [j for j in pin_idx if (rig.ancestors[j][rig.dof_joint] & active).any()]
        for j in kept_idx:
            active |= rig.ancestors[j][rig.dof_joint]
        self.columns = np.nonzero(active)[0]
        self.pin_frames = np.array(kept_idx, np.int64)
        self.pin_local = np.array([p.point for p in kept], float).reshape(-1, 3)
        self.pin_rot_frames = np.array([j for p, j in zip(kept, kept_idx, strict=True) if p.orientation], np.int64)


def _points(wpos: F, wmat: F, frames: NDArray[np.int64], local: F) -> F:
    return wpos[frames] + np.einsum("nij,nj->ni", wmat[frames], local)


def _rot_error(target: F, current: F) -> F:
    """World rotation vectors taking ``current`` (matrices ``[P,3,3]``) to ``target`` (quaternions), ``[P*3]``."""
    if target.shape[0] == 0:
        return np.zeros(0)
    return quat.log(quat.mul(target, quat.conjugate(quat.from_matrix(current)))).reshape(-1)


def solve_ik(
    rig: IKRig,
    root: ArrayLike,
    rotations: ArrayLike,
    effectors: tuple[Effector, ...] | list[Effector],
    pins: tuple[Pin, ...] | list[Pin] = (),
    *,
    offsets: ArrayLike | None = None,
    settings: IKSettings = IKSettings(),
) -> IKResult:
    """Move the effectors to their targets by changing the rig's attributes (thesis Eq. 4.13).

    Args:
        rig: coordinates, limits and stiffness.
        root: ``[3]`` root position; rotations: ``[J,4]`` local rotations (the input pose).
        effectors: targets for any joints.
        pins: points (and optionally orientations) held at their input state within ``ε``.
        offsets: per-puppet bone offsets (default: the skeleton's).
        settings: weights and tolerances.

    Returns:
        An :class:`IKResult`; ``reached`` is False when the target was rejected as
        unreachable, and then ``root``/``rotations`` are the input pose.
    """
    sk = rig.skeleton
    root0 = np.asarray(root, dtype=np.float64).reshape(3)
    rot0 = np.asarray(rotations, dtype=np.float64).reshape(sk.num_joints, 4)
    if not (np.isfinite(root0).all() and np.isfinite(rot0).all()):
        raise ValueError("input pose has NaN or infinite values")
    prob = _Problem(rig, tuple(effectors), tuple(pins))
    cols = prob.columns
    c, pre = rig.to_coordinates(root0, rot0)
    stiff2 = settings.w_d * rig.stiffness[cols] ** 2 + settings.regularization

    def evaluate(cc: F) -> tuple[F, F, F, F, F]:
        r, q = rig.to_pose(cc, pre, root0)
        wpos, wrot = fk_matrices(sk, r, q, offsets)
        ds = np.concatenate([
            (prob.pos_target - _points(wpos, wrot, prob.pos_frames, prob.pos_local)).reshape(-1),
            settings.orientation_scale * _rot_error(prob.rot_target, wrot[prob.rot_frames]),
        ])  # fmt: skip
        rho = _points(wpos, wrot, prob.pin_frames, prob.pin_local).reshape(-1)
        return wpos, wrot, ds, rho, q

    wpos, wrot, ds, rho, _ = evaluate(c)
    rho_target = rho.copy()
    pin_rot_target = quat.from_matrix(wrot[prob.pin_rot_frames]).reshape(-1, 4)
    n_pin_pos = 3 * prob.pin_frames.size

    def pin_residual(rho_now: F, wrot_now: F) -> F:
        pos = rho_target[:n_pin_pos] - rho_now[:n_pin_pos]
        rot = settings.orientation_scale * _rot_error(pin_rot_target, wrot_now[prob.pin_rot_frames])
        return np.concatenate([pos, rot])

    n_eff = prob.pos_frames.size + prob.rot_frames.size
    eps = settings.pin_epsilon
    # Length scale of the task-space trust region: the longest chain above an effector.
    bone = np.linalg.norm(offsets if offsets is not None else sk.offsets, axis=-1).reshape(-1)
    bone[0] = 0.0
    chain_len = rig.ancestors.astype(float) @ bone
    reach = float(np.max(chain_len[prob.pos_frames] + np.linalg.norm(prob.pos_local, axis=-1), initial=0.0))
    reach = max(reach, settings.orientation_scale)

    def error_of(d: F) -> float:
        """Largest per-effector miss (metres; orientations scaled by ``orientation_scale``)."""
        return float(np.max(np.linalg.norm(d.reshape(n_eff, 3), axis=-1), initial=0.0))

    def merit(d: F, pins_now: F) -> float:
        excess = np.maximum(np.abs(pins_now) - eps, 0.0)
        return float(np.linalg.norm(d) + np.linalg.norm(excess))

    def converged(d: F, pins_now: F) -> bool:
        return error_of(d) < settings.tolerance and (pins_now.size == 0 or float(np.max(np.abs(pins_now))) <= eps)

    m = n_pin_pos + 3 * prob.pin_rot_frames.size
    qp = StepQP(cols.size, ds.size, m)
    radius = settings.trust_radius
    drho = pin_residual(rho, wrot)
    cur = merit(ds, drho)
    best_c, best, strikes, it = c.copy(), cur, 0, 0
    band = 0.9 * eps  # margin for the linearisation error, so the true pins end within ε
    w_m = settings.w_m / settings.length_unit**2
    done = converged(ds, drho)
    while not done and it < settings.max_iterations and strikes < settings.patience:
        it += 1
        axes = dof_axes(rig, c, wrot)
        eff_points = _points(wpos, wrot, prob.pos_frames, prob.pos_local)
        js = np.vstack([
            point_jacobian(rig, axes, wpos, prob.pos_frames, eff_points, cols),
            settings.orientation_scale * orientation_jacobian(rig, axes, prob.rot_frames, cols),
        ])  # fmt: skip
        jr = np.vstack([
            point_jacobian(rig, axes, wpos, prob.pin_frames, rho.reshape(-1, 3), cols),
            settings.orientation_scale * orientation_jacobian(rig, axes, prob.pin_rot_frames, cols),
        ])  # fmt: skip
        # Trust region: per-coordinate box, and each effector's wanted move clamped in length.
        want = ds.reshape(n_eff, 3)
        norms = np.linalg.norm(want, axis=-1, keepdims=True)
        limit = radius * reach
        want = want * np.minimum(1.0, limit / np.maximum(norms, 1e-12))
        lo_lim, hi_lim = rig.lower[cols] - c[cols], rig.upper[cols] - c[cols]
        lo, hi = np.maximum(lo_lim, -radius), np.minimum(hi_lim, radius)
        bad = lo > hi  # only when the input already breaks a limit: step straight back inside
        back = np.clip(0.0, lo_lim, hi_lim)
        lo[bad], hi[bad] = back[bad], back[bad]
        step = qp.solve(w_m, stiff2, js, want.reshape(-1), jr, drho - band, drho + band, lo, hi)
        if step is None:
            strikes += 1
            radius *= 0.5
            continue
        trial = c.copy()
        # The QP meets bounds to its tolerance only; clip so limits hold exactly (when the input did).
        inside = (c[cols] >= rig.lower[cols]) & (c[cols] <= rig.upper[cols])
        moved = c[cols] + step
        trial[cols] = np.where(inside, np.clip(moved, rig.lower[cols], rig.upper[cols]), moved)
        t_wpos, t_wrot, t_ds, t_rho, _ = evaluate(trial)
        t_drho = pin_residual(t_rho, t_wrot)
        t_merit = merit(t_ds, t_drho)
        if t_merit < cur or converged(t_ds, t_drho):
            c, wpos, wrot, ds, rho, drho, cur = trial, t_wpos, t_wrot, t_ds, t_rho, t_drho, t_merit
            radius = min(radius * 1.5, settings.max_trust_radius)
        else:
            radius *= 0.5
        done = converged(ds, drho)
        if done or cur < best * (1.0 - 1e-3):
            best, best_c, strikes = cur, c.copy(), 0
        else:
            strikes += 1  # §4.2.3: the effector did not get closer

    best_root, best_rot = rig.to_pose(best_c, pre, root0)
    out_root, out_rot = (best_root, best_rot) if done else (root0.copy(), rot0.copy())
    b_wpos, b_wrot, b_ds, b_rho, _ = evaluate(best_c)
    return IKResult(
        root=out_root,
        rotations=out_rot,
        reached=done,
        iterations=it,
        error=error_of(b_ds),
        pin_error=float(np.max(np.abs(pin_residual(b_rho, b_wrot)), initial=0.0)),
        closest_root=best_root,
        closest_rotations=best_rot,
        coordinates=best_c,
    )
