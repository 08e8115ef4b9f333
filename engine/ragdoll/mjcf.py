"""MJCF generation: ragdolls, props and the ground as one MuJoCo model (Y up).

We keep the engine's convention inside MuJoCo rather than converting at the boundary:
gravity is ``(0, -9.81, 0)`` and the ground plane's normal is +Y, so positions and
quaternions cross between engine and physics unchanged. Each MuJoCo body frame *is*
the skeleton joint's frame (body offset = bone offset, identity rest rotation), so a
ball joint's ``qpos`` quaternion is exactly the joint's local rotation and the root's
free joint is the root's world transform — reading a pose back is a gather, not a solve.

Self-collision only where it helps: bodies closer than three links in the tree, and
bodies whose capsules already touch in the rest pose, are excluded pairwise (per
ragdoll, so two ragdolls still collide everywhere); hands still hit the hips, one leg
still blocks the other.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.fk import forward_kinematics
from engine.ragdoll.profile import RagdollProfile, bone_segments, servo_gains
from engine.skeleton import Skeleton

# (contype, conaffinity) of each kind of geom; two geoms touch when either's type meets the
# other's affinity. Simulated bodies touch everything; animated (kinematic) bodies touch only
# simulated bodies and props (neither the ground nor each other can give way); ghosts -- ragdolls
# that overlap another ragdoll deeply, until they are apart -- touch only the ground and props,
# so two puppets dropped on one spot separate instead of exploding.
GROUND_BITS = (16, 0)
SIMULATED_BITS = (3, 23)
PROP_BITS = (11, 31)
ANIMATED_BITS = (4, 2)
GHOST_BITS = (8, 16)

__all__ = [
    "GROUND_BITS",
    "SIMULATED_BITS",
    "PROP_BITS",
    "ANIMATED_BITS",
    "GHOST_BITS",
    "RagdollSpec",
    "PropSpec",
    "RagdollFragment",
    "ragdoll_fragment",
    "build_mjcf",
    "rd_name",
    "prop_name",
    "self_collision_excludes",
]


@dataclass(frozen=True)
class RagdollSpec:
    """One ragdoll in the physics model: the puppet entity id and how to build it."""

    key: int
    skeleton: Skeleton
    profile: RagdollProfile
    offsets: NDArray[np.float64]


@dataclass(frozen=True)
class PropSpec:
    """One sphere prop (a snowball): entity id, radius (m), mass (kg) and friction."""

    key: int
    radius: float
    mass: float
    friction: float = 1.0


@dataclass(frozen=True)
class RagdollFragment:
    """One ragdoll's MJCF lines per section, with its full-strength servo gains.

    Rendering is the slow part of a rebuild (contact filtering is O(J²)), and a ragdoll's
    lines never change, so the physics world renders each ragdoll once and reuses it.
    """

    spec: RagdollSpec
    body: tuple[str, ...]
    contact: tuple[str, ...]
    equality: tuple[str, ...]
    actuator: tuple[str, ...]
    kp: NDArray[np.float64]
    kv: NDArray[np.float64]


def rd_name(key: int, part: str) -> str:
    """MuJoCo name of a ragdoll part (body, joint, actuator, site) for puppet ``key``."""
    return f"rd{key}_{part}"


def prop_name(key: int) -> str:
    """MuJoCo name of prop ``key``'s body, free joint and geom."""
    return f"pr{key}"


def _f(values: NDArray[np.float64] | tuple[float, ...] | float) -> str:
    return " ".join(f"{float(v):.17g}" for v in np.atleast_1d(np.asarray(values, dtype=np.float64)))


def _segment_distance(
    a0: NDArray[np.float64], a1: NDArray[np.float64], b0: NDArray[np.float64], b1: NDArray[np.float64]
) -> float:
    """Closest distance between segments ``a0a1`` and ``b0b1`` (degenerate segments allowed)."""
    d1, d2, r = a1 - a0, b1 - b0, a0 - b0
    a, e, f = float(d1 @ d1), float(d2 @ d2), float(d2 @ r)
    if a < 1e-12 and e < 1e-12:
        return float(np.linalg.norm(r))
    if a < 1e-12:
        s, t = 0.0, np.clip(f / e, 0.0, 1.0)
    else:
        c = float(d1 @ r)
        if e < 1e-12:
            s, t = np.clip(-c / a, 0.0, 1.0), 0.0
        else:
            b = float(d1 @ d2)
            den = a * e - b * b
            s = np.clip((b * f - c * e) / den, 0.0, 1.0) if den > 1e-12 else 0.0
            t = (b * s + f) / e
            if t < 0.0:
                s, t = np.clip(-c / a, 0.0, 1.0), 0.0
            elif t > 1.0:
                s, t = np.clip((b - c) / a, 0.0, 1.0), 1.0
    return float(np.linalg.norm((a0 + s * d1) - (b0 + t * d2)))


def self_collision_excludes(
    skeleton: Skeleton, profile: RagdollProfile, offsets: NDArray[np.float64], min_links: int = 3, margin: float = 0.01
) -> list[tuple[int, int]]:
    """Joint pairs that must not collide: fewer than ``min_links`` apart, or touching at rest."""
    n = skeleton.num_joints
    anc = [[j] for j in range(n)]
    for j in range(1, n):
        anc[j] = [j, *anc[int(skeleton.parents[j])]]
    p0, p1, r = bone_segments(skeleton, profile.radii, offsets)
    wpos, wrot = forward_kinematics(skeleton, offsets[0], quat.identity(n), offsets)
    w0, w1 = wpos + quat.rotate(wrot, p0), wpos + quat.rotate(wrot, p1)
    out = []
    for a in range(n):
        for b in range(a + 1, n):
            common = next(x for x in anc[b] if x in anc[a])
            links = anc[a].index(common) + anc[b].index(common)
            if links < min_links or _segment_distance(w0[a], w1[a], w0[b], w1[b]) < r[a] + r[b] + margin:
                out.append((a, b))
    return out


def ragdoll_fragment(spec: RagdollSpec) -> RagdollFragment:
    """Render one ragdoll: nested bodies, self-collision excludes, pin and holds, muscles."""
    body: list[str] = []
    contact: list[str] = []
    equality: list[str] = []
    actuator: list[str] = []
    sk, pr, off, k = spec.skeleton, spec.profile, spec.offsets, spec.key
    p0, p1, r = bone_segments(sk, pr.radii, off)
    kp, kv = servo_gains(sk, pr, off)
    damping = pr.joint_damping * kv
    # armature (rotor inertia) steadies the implicit step; kept small against each subtree
    armature = np.maximum(0.05 * kv / (2.0 * max(pr.damping_ratio, 0.5) * pr.frequency), 1e-4)
    children: list[list[int]] = [[] for _ in range(sk.num_joints)]
    for j in range(1, sk.num_joints):
        children[int(sk.parents[j])].append(j)

    def emit(j: int, depth: int) -> None:
        pad = "  " * depth
        name = rd_name(k, sk.names[j])
        body.append(f'{pad}<body name="{name}" pos="{_f(off[j])}">')
        kind = pr.kinds[j]
        if kind == "free":
            body.append(f'{pad}  <freejoint name="{name}"/>')
            body.append(f'{pad}  <site name="{name}_pin"/>')
        elif kind == "ball":
            body.append(
                f'{pad}  <joint name="{name}" type="ball" range="0 {_f(pr.cone[j])}" solreflimit="0.005 1" solimplimit="0.95 0.99 0.001" '
                f'damping="{_f(damping[j])}" armature="{_f(armature[j])}"/>'
            )
            actuator.append(f'<orientation name="{name}" joint="{name}" kp="{_f(kp[j])}" kv="{_f(kv[j])}"/>')
        else:
            body.append(
                f'{pad}  <joint name="{name}" type="hinge" axis="{_f(pr.hinge_axis[j])}" '
                f'range="{_f(pr.hinge_range[j])}" solreflimit="0.005 1" solimplimit="0.95 0.99 0.001" damping="{_f(damping[j])}" '
                f'armature="{_f(armature[j])}"/>'
            )
            actuator.append(f'<position name="{name}" joint="{name}" kp="{_f(kp[j])}" kv="{_f(kv[j])}"/>')
        friction = f'friction="{_f(pr.friction)} 0.02 0.01"'
        if np.allclose(p0[j], p1[j]):
            body.append(
                f'{pad}  <geom name="{name}" type="sphere" pos="{_f(p0[j])}" size="{_f(r[j])}" '
                f'mass="{_f(pr.masses[j])}" {friction}/>'
            )
        else:
            body.append(
                f'{pad}  <geom name="{name}" type="capsule" fromto="{_f(p0[j])} {_f(p1[j])}" '
                f'size="{_f(r[j])}" mass="{_f(pr.masses[j])}" {friction}/>'
            )
        if sk.names[j] in pr.holdable:
            body.append(f'{pad}  <site name="{name}_hold" pos="{_f(0.5 * (p0[j] + p1[j]))}"/>')
            equality.append(
                f'<connect name="{name}_hold" site1="{name}_hold" site2="{rd_name(k, "hold")}" '
                f'active="false" solref="0.06 0.6"/>'
            )
        for c in children[j]:
            emit(c, depth + 1)
        body.append(f"{pad}</body>")

    emit(0, 2)
    root = rd_name(k, sk.names[0])
    for part in ("pin", "hold"):
        body.append(
            f'    <body name="{rd_name(k, part)}" mocap="true" pos="{_f(off[0])}">'
            f'<site name="{rd_name(k, part)}"/></body>'
        )
    equality.append(
        f'<weld name="{rd_name(k, "pin")}" site1="{root}_pin" site2="{rd_name(k, "pin")}" '
        f'active="false" solref="0.02 1"/>'
    )
    for a, b in self_collision_excludes(sk, pr, off):
        contact.append(f'<exclude body1="{rd_name(k, sk.names[a])}" body2="{rd_name(k, sk.names[b])}"/>')
    return RagdollFragment(spec, tuple(body), tuple(contact), tuple(equality), tuple(actuator), kp, kv)


def build_mjcf(
    ragdolls: Sequence[RagdollSpec | RagdollFragment],
    props: Sequence[PropSpec],
    timestep: float,
    ground_friction: float = 1.0,
    sleep: bool = False,
) -> str:
    """The whole physics scene as an MJCF string, ragdolls (specs or rendered) and props in the order given
    (``sleep``: enable MuJoCo's sleeping, with which the ragdoll pool parks its free slots)."""
    body: list[str] = []
    contact: list[str] = []
    equality: list[str] = []
    actuator: list[str] = []
    for item in ragdolls:
        frag = item if isinstance(item, RagdollFragment) else ragdoll_fragment(item)
        body += frag.body
        contact += frag.contact
        equality += frag.equality
        actuator += frag.actuator
    for p in props:
        n = prop_name(p.key)
        # condim 6: rolling and torsional friction, so a snowball slows down as it rolls.
        body.append(
            f'    <body name="{n}" pos="0 {_f(p.radius)} 0"><freejoint name="{n}"/>'
            f'<geom name="{n}" type="sphere" size="{_f(p.radius)}" mass="{_f(p.mass)}" condim="6" '
            f'contype="{PROP_BITS[0]}" conaffinity="{PROP_BITS[1]}" '
            f'friction="{_f(p.friction)} 0.005 0.002"/></body>'
        )
    sections = [
        '<mujoco model="puppetphone">',
        '  <compiler angle="radian" autolimits="true"/>',
        # stiff contacts (5 ms, critically damped): snowballs and bodies barely sink into anything
        # contype/conaffinity: see CONTACT_BITS; ragdoll bodies start simulated, _control.py
        # switches them to animated or ghost
        f'  <default><geom solref="0.005 1" solimp="0.95 0.99 0.001" contype="{SIMULATED_BITS[0]}" '
        f'conaffinity="{SIMULATED_BITS[1]}"/></default>',
        # sleeping parks the pool's free ragdoll slots (engine.ragdoll._pool); nothing falls asleep by itself
        (
            f'  <option timestep="{_f(timestep)}" gravity="0 -9.81 0" integrator="implicitfast"'
            + ('><flag sleep="enable"/></option>' if sleep else "/>")
        ),
        "  <worldbody>",
        f'    <geom name="ground" type="plane" size="0 0 1" zaxis="0 1 0" contype="{GROUND_BITS[0]}" conaffinity="{GROUND_BITS[1]}" friction="{_f(ground_friction)} 0.005 0.002"/>',
        *body,
        "  </worldbody>",
    ]
    for tag, items in (("contact", contact), ("equality", equality), ("actuator", actuator)):
        if items:
            sections += [f"  <{tag}>", *("    " + s for s in items), f"  </{tag}>"]
    sections.append("</mujoco>")
    return "\n".join(sections)
