"""``PhysicsWorld``: one MuJoCo model and data holding every ragdoll and prop.

Why MuJoCo: it is fast (a 17-body ragdoll steps in tens of microseconds here), bitwise
deterministic on the same build and CPU (our replays need that), has implicit PD servos
for ball joints (the geodesic ``orientation`` actuator) so muscles stay stable at any
stiffness, and soft equality constraints (weld, connect) to mocap bodies for the root
pin and the MotionStick's hold. pybullet has no ball-joint servos and is no longer
developed.

Control is *command* based: :meth:`drive` stores a ragdoll's target pose and weights,
and :meth:`step` applies the commands of every ragdoll in one vectorised pass
(:mod:`engine.ragdoll._control` over :mod:`engine.ragdoll._layout`) before running ``substeps`` MuJoCo steps in C.

Ragdolls live in a pool of slots compiled once (:mod:`engine.ragdoll._pool`): a ragdoll joining
or leaving the simulation borrows or returns a slot (a state copy and a sleep flag), never a
compile. The model is recompiled only when the pool grows (in chunks, with headroom) or a prop is
added or removed; every body that existed keeps its exact state, carried over by name
(:mod:`engine.ragdoll._carry`).
Snowballs change radius in place (geom size, bounds, mass, inertia, ``mj_setConst``).
Each step is guarded (:mod:`engine.ragdoll._guard`): velocities are bounded, and a step
MuJoCo cannot take is undone and counted in :attr:`PhysicsWorld.recoveries`.
"""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
from numpy.typing import ArrayLike

from engine import jit, quat
from engine.arrays import F64 as _F
from engine.arrays import I64
from engine.pose import Pose
from engine.ragdoll._bounds import KindTable, command_boxes, geom_boxes, posed_boxes
from engine.ragdoll._bounds import load as load_box_kernel
from engine.ragdoll._building import Building
from engine.ragdoll._commands import Commands, joint_rows
from engine.ragdoll._control import apply_commands, place, project_twist
from engine.ragdoll._detail import Detail
from engine.ragdoll._drive_kernel import load as load_drive_kernels
from engine.ragdoll._guard import PhysicsRecovery, collect_warnings, guarded_step
from engine.ragdoll._islands import LOOKAHEAD, ghosts, near_boxes, near_simulated, reach
from engine.ragdoll._layout import Layout
from engine.ragdoll._pool import RagdollPool, kind_of
from engine.ragdoll._readback import Readback
from engine.ragdoll._slots import PropSlot, RagdollSlot
from engine.ragdoll.mjcf import PropSpec, RagdollSpec, rd_name
from engine.ragdoll.profile import RagdollProfile
from engine.skeleton import Skeleton

__all__ = ["PhysicsWorld"]

_STATE = mujoco.mjtState.mjSTATE_INTEGRATION


class PhysicsWorld(Readback, Building):
    """The physics resource: ragdolls and props keyed by their entity id.

    Args:
        timestep: MuJoCo step in seconds.
        substeps: MuJoCo steps per simulation step (``timestep * substeps`` should equal ``World.dt``).
        ground_friction: sliding friction of the ground plane.
        crowd_substeps: MuJoCo steps per simulation step while the model holds a crowd
            (:mod:`engine.ragdoll._detail`; no switch unless fewer than ``substeps``).
    """

    SIM_STATE = True

    def __init__(
        self, timestep: float = 1.0 / 480.0, substeps: int = 8, ground_friction: float = 1.0, crowd_substeps: int = 5
    ) -> None:
        if timestep <= 0 or substeps < 1 or crowd_substeps < 1:
            raise ValueError("timestep must be positive and substeps at least 1")
        self.timestep = timestep
        self.substeps = substeps
        self.detail = Detail(substeps, crowd_substeps, timestep * substeps)
        self.ground_friction = ground_friction
        self.model: mujoco.MjModel | None = None
        self.data: mujoco.MjData | None = None
        self.layout: Layout | None = None
        self.rebuilds = 0
        self._ragdolls: dict[int, RagdollSlot] = {}
        self._cmds = Commands()
        self._changes = 0
        # the physics stage's record of what it last synced the ragdolls from (a world query's
        # result and :attr:`ragdoll_changes` then: engine.ragdoll.system)
        self.synced: tuple[object, int] | None = None
        self._props: dict[int, PropSlot] = {}
        self._held: set[int] = set()  # ragdolls with a held body
        self._dirty = False
        self._sized = True
        self._moved = False
        self._new_data = False
        self._pool = RagdollPool()
        self._reach: dict[bytes, float] = {}
        self._kinds = KindTable()  # the kinds' capsules for the compiled command boxes
        self._loaded = False  # whether the compiled control kernels were loaded (ensure_built)
        self.left_out = 0  # ragdolls that should have joined at the last change but the full pool had no room
        self._pool_layout: Layout | None = None
        self._digest = b""
        self._ke: _F | None = None
        self._read: tuple[_F, _F] | None = None
        self.simulate_animated = False
        self.recoveries = 0
        self._limit = np.zeros(0)
        self._owners = np.zeros(0, dtype=np.int64)
        collect_warnings()

    @property
    def dt(self) -> float:
        """Seconds advanced by one :meth:`step`."""
        return self.timestep * self.substeps

    # -- membership ---------------------------------------------------------------------
    def add_ragdoll(
        self,
        key: int,
        skeleton: Skeleton,
        profile: RagdollProfile,
        root: ArrayLike,
        rotations: ArrayLike,
        offsets: ArrayLike | None = None,
    ) -> None:
        """Add a ragdoll for puppet ``key`` at rest in the given pose (built at the next use)."""
        if key in self._ragdolls or key in self._props:
            raise ValueError(f"entity {key} is already in the physics world")
        if profile.num_joints != skeleton.num_joints:
            raise ValueError(f"profile has {profile.num_joints} joints, skeleton {skeleton.num_joints}")
        off = np.array(skeleton.offsets if offsets is None else offsets, dtype=np.float64).reshape(-1, 3)
        r, q = self._checked(key, root, rotations, skeleton.num_joints)
        spec = RagdollSpec(key, skeleton, profile, off)
        kind = kind_of(spec)
        if kind not in self._reach:  # a crowd is a few kinds of ragdoll many times over
            self._reach[kind] = reach(skeleton, profile, off)
        self._ragdolls[key] = RagdollSlot(spec, kind, skeleton.num_joints)
        self._cmds.add(key, r, q, self._reach[kind])
        self._changes += 1
        self._sized = False

    def add_prop(
        self,
        key: int,
        radius: float,
        mass: float,
        position: ArrayLike,
        rotation: ArrayLike | None = None,
        velocity: ArrayLike | None = None,
        friction: float = 1.0,
    ) -> None:
        """Add a sphere prop (snowball) for entity ``key`` (built at the next use)."""
        if key in self._ragdolls or key in self._props:
            raise ValueError(f"entity {key} is already in the physics world")
        if not (radius > 0 and mass > 0 and np.isfinite(radius) and np.isfinite(mass)):
            raise ValueError(f"prop radius and mass must be positive and finite, got {radius}, {mass}")
        rot = quat.identity() if rotation is None else quat.normalize(np.asarray(rotation, dtype=np.float64))
        vel = np.zeros(6) if velocity is None else np.asarray(velocity, dtype=np.float64).reshape(6)
        init = (np.array(position, dtype=np.float64).reshape(3), rot, vel)
        self._props[key] = PropSlot(PropSpec(key, float(radius), float(mass), friction), init=init)
        self._dirty = True

    def remove(self, key: int) -> None:
        """Remove a ragdoll or prop (no error if absent)."""
        slot = self._ragdolls.pop(key, None)
        self._held.discard(key)
        if slot is not None:
            self._changes += 1
            C = self.commands
            i = C.row[key]
            if C.pool[i] >= 0:
                self._give_back(i)
            C.remove(key)
        if self._props.pop(key, None) is not None:
            self._dirty = True

    def has_ragdoll(self, key: int) -> bool:
        """Whether puppet ``key`` has a ragdoll here."""
        return key in self._ragdolls

    def has_prop(self, key: int) -> bool:
        """Whether entity ``key`` is a prop here."""
        return key in self._props

    @property
    def ragdoll_keys(self) -> list[int]:
        """Entity ids of the ragdolls, in order."""
        return sorted(self._ragdolls)

    @property
    def ragdoll_changes(self) -> int:
        """How many ragdolls were added or removed so far (a cheap "did the set change" check)."""
        return self._changes

    @property
    def prop_keys(self) -> list[int]:
        """Entity ids of the props, in order."""
        return sorted(self._props)

    # -- building -----------------------------------------------------------------------
    def ensure_built(self) -> None:
        """Compile the model when the pool must grow or props were added or removed (keeping every
        state), then lend pool slots to ragdolls that joined the simulation and park those that left."""
        if self._dirty or not self._sized:
            self._size_pool()
        if self._dirty:
            self._compile()
            if jit.enabled() and not self._loaded:  # the control kernels, at a step that compiles anyway
                load_drive_kernels()
                load_box_kernel()
                self._loaded = True
        if self._moved:
            self._assign()

    # -- commands -------------------------------------------------------------------------
    @property
    def commands(self) -> Commands:
        """The ragdolls' command columns, rows in key order (current: added and removed ones applied)."""
        self._cmds.sync()
        return self._cmds

    def _checked(self, key: int, root: ArrayLike, rotations: ArrayLike, n: int) -> tuple[_F, _F]:
        r = np.array(root, dtype=np.float64).reshape(3)
        q = np.asarray(rotations, dtype=np.float64)
        if q.shape != (n, 4):
            raise ValueError(f"ragdoll {key}: rotations must be [{n},4], got {list(q.shape)}")
        if not (np.isfinite(r).all() and np.isfinite(q).all()):
            raise ValueError(f"ragdoll {key}: target pose has NaN or infinite values")
        return r, quat.normalize(q)

    def _slot(self, key: int) -> RagdollSlot:
        try:
            return self._ragdolls[key]
        except KeyError:
            raise KeyError(f"entity {key} has no ragdoll in the physics world") from None

    def drive(
        self,
        key: int,
        root: ArrayLike,
        rotations: ArrayLike,
        muscle: float,
        pin: float,
        gravity_support: float = 0.0,
        kinematic: bool = False,
    ) -> None:
        """Set the ragdoll's command for the next steps.

        Args:
            key: the puppet.
            root: target world position of the root joint.
            rotations: ``[J,4]`` target local rotations (the root's is its world rotation).
            muscle: muscle weight 0..1 scaling every servo (stiffness ∝ w, damping ∝ √w, so the
                damping ratio stays the same at every weight).
            pin: pin weight 0..1 of the weld between the root and its animated target.
            gravity_support: 0..1 share of each body's weight carried by its muscles.
            kinematic: place the bodies exactly on the target with its velocity (the *animated*
                mode), so the props they touch get a real push.
        """
        slot = self._slot(key)
        r, q = self._checked(key, root, rotations, slot.spec.skeleton.num_joints)
        C = self.commands
        i = C.row[key]
        C.root[i], C.rot[C.starts[i] : C.starts[i + 1]], C.kinematic[i] = r, q, bool(kinematic)
        C.muscle[i], C.pin[i] = float(np.clip(muscle, 0, 1)), float(np.clip(pin, 0, 1))
        C.support[i] = float(np.clip(gravity_support, 0, 1))

    def drive_simulated(self, keys: list[int], roots: _F, rotations: _F, muscle: _F, pin: _F, support: _F) -> None:
        """:meth:`drive` (not kinematic) for many ragdolls at once: roots ``[n,3]``, their rotations end
        to end ``[ΣJ,4]``, weights ``[n]`` (validated and normalised in one pass, each number as
        :meth:`drive` makes it: ten puppets falling in a crowd are ten drives a step)."""
        if not len(keys):
            return
        C = self.commands
        rows = C.rows(keys)
        r = np.asarray(roots, dtype=np.float64).reshape(len(rows), 3)
        q = np.asarray(rotations, dtype=np.float64)
        sizes: I64 = C.joints[rows]
        if q.shape != (int(sizes.sum()), 4):
            raise ValueError(f"rotations must be [J,4] per ragdoll with J = {sizes.tolist()}")
        ends: I64 = np.cumsum(sizes)
        ok = np.isfinite(r).all(axis=1) & np.logical_and.reduceat(np.isfinite(q).all(axis=1), ends - sizes)
        if not ok.all():
            raise ValueError(f"ragdoll {keys[int(np.argmin(ok))]}: target pose has NaN or infinite values")
        C.root[rows], C.rot[joint_rows(C.starts, rows)], C.kinematic[rows] = r, quat.normalize(q), False
        C.muscle[rows], C.pin[rows] = np.clip(muscle, 0, 1), np.clip(pin, 0, 1)
        C.support[rows] = np.clip(support, 0, 1)

    def drive_animated(self, keys: list[int] | I64, roots: list[_F] | _F, rotations: list[_F] | _F) -> list[int]:
        """:meth:`drive` ``kinematic=True`` for many ragdolls at once (validated and normalised
        in one pass: a crowd of animated puppets is most of the physics stage's Python work).

        ``roots`` is ``[P, 3]`` (or a list of ``[3]``); ``rotations`` a list of ``[J, 4]`` per ragdoll,
        or ``[P, J, 4]`` when all have ``J`` joints. A target with NaN or infinite values is not
        taken: that ragdoll keeps its previous command (see :meth:`target`), so a bad pose never
        reaches MuJoCo.

        Returns:
            The keys whose targets were refused.
        """
        if not len(keys):
            return []
        C = self.commands
        want = np.asarray(keys, dtype=np.int64)
        whole = C.whole(want)
        rows = np.arange(len(want), dtype=np.int64) if whole else C.rows(want)
        sizes: I64 = C.joints[rows]
        r = np.array(roots, dtype=np.float64).reshape(len(keys), 3)
        stacked = isinstance(rotations, np.ndarray) and rotations.ndim == 3
        if stacked:
            q = np.asarray(rotations, dtype=np.float64).reshape(-1, 4)
        else:
            q = np.concatenate([np.asarray(x, dtype=np.float64) for x in rotations])
        if q.shape != (int(sizes.sum()), 4):
            raise ValueError(f"rotations must be [J,4] per ragdoll with J = {sizes.tolist()}")
        finite = np.isfinite(q)
        if whole and finite.all() and np.isfinite(r).all():
            # the whole crowd in key order, every target good (a walking crowd): nothing to refuse or select
            C.root[:] = r
            C.rot[:] = quat.normalize(q)
            C.kinematic[:] = True
            C.muscle[:] = C.pin[:] = C.support[:] = 1.0
            return []
        ends: I64 = np.cumsum(sizes)  # numpy's stubs leave a cumsum of ints untyped
        ok = np.isfinite(r).all(axis=1) & np.logical_and.reduceat(finite.all(axis=1), ends - sizes)
        q = quat.normalize(np.where(finite, q, quat.identity()))  # refused rows are not used
        good = rows[ok]
        C.root[good] = r[ok]
        C.rot[joint_rows(C.starts, good)] = q[np.repeat(ok, sizes)]
        C.kinematic[rows] = True
        C.muscle[rows] = C.pin[rows] = C.support[rows] = 1.0
        return list(want[~ok].tolist())

    def target(self, key: int) -> Pose:
        """The ragdoll's current command (its last accepted target pose)."""
        self._slot(key)
        root, rot = self.commands.pose(self.commands.row[key])
        return Pose(root.copy(), rot.copy())

    def hold(self, key: int, joint: str | None, target: ArrayLike | None = None) -> None:
        """Hold one body of the ragdoll by a spring at ``target`` (``joint=None`` lets go)."""
        slot = self._slot(key)
        if joint is not None and joint not in slot.spec.profile.holdable:
            raise KeyError(f"joint {joint!r} is not holdable; holdable are {', '.join(slot.spec.profile.holdable)}")
        t = None if target is None else np.array(target, dtype=np.float64).reshape(3)
        if t is not None and not np.isfinite(t).all():
            raise ValueError(f"ragdoll {key}: hold target has NaN or infinite values")
        C = self.commands
        i = C.row[key]
        C.hold[i] = joint
        if joint is None:
            self._held.discard(key)
        else:
            self._held.add(key)
        if t is not None:
            C.hold_target[i] = t

    def holding(self) -> list[int]:
        """The ragdolls whose body is held now (so a crowd's physics stage lets go of those only)."""
        return sorted(self._held)

    def set_pose(self, key: int, root: ArrayLike, rotations: ArrayLike) -> None:
        """Place the ragdoll on a pose at rest now (teleport); the next step has no target velocity."""
        self.ensure_built()
        slot = self._slot(key)
        r, q = self._checked(key, root, rotations, slot.spec.skeleton.num_joints)
        C = self.commands
        i = C.row[key]
        C.root[i], C.rot[C.starts[i] : C.starts[i + 1]] = r, q
        if not C.in_model[i]:
            C.has_last[i] = False
            return
        assert self.layout is not None and self.model is not None and self.data is not None
        at_rest = np.zeros(1, dtype=bool)
        place(self.layout, self.data, np.array([self.layout.ordinal(key)]), r[None], q, r[None], q, at_rest, self.dt)
        C.has_last[i] = False
        self._ke = self._read = None
        mujoco.mj_forward(self.model, self.data)

    def _place_rows(self, rows: I64) -> None:
        """Put ragdolls ``rows`` (command rows, ascending, just given pool slots) where their animation
        was a step ago, moving as it moved then (as if simulated all along, so they keep their momentum);
        at rest there without a step before it, and at rest on the target without a last one."""
        C, L, d = self._cmds, self.layout, self.data
        assert L is not None and d is not None
        has = C.has_last[rows]
        j = joint_rows(C.starts, rows)
        root = np.where(has[:, None], C.last_root[rows], C.root[rows])
        rot = np.where(np.repeat(has, C.joints[rows])[:, None], C.last_rot[j], C.rot[j])
        ordinals = np.searchsorted(np.asarray(L.keys, dtype=np.int64), C.keys[rows])
        place(L, d, ordinals, root, rot, C.prev_root[rows], C.prev_rot[j], has & C.has_prev[rows], self.dt)
        self._ke = self._read = None

    # -- stepping -----------------------------------------------------------------------
    def step(self) -> None:
        """Apply every command, advance one simulation step (``substeps`` MuJoCo steps) and
        enforce the twist limits. Animated ragdolls far from anything simulated are left out
        of the model first (:mod:`engine.ragdoll._islands`)."""
        self._update_islands()
        self.ensure_built()
        C = self.commands
        out = np.nonzero(~C.in_model)[0]
        if len(out):  # it moves with its target: where it was is its last target
            C.roll(out, keep_prev=True)
        if self.model is None or self.data is None:
            return
        assert self.layout is not None
        L, d = self.layout, self.data
        rows = C.rows(L.keys)
        roots = d.qpos[L.root_q[:, None] + np.arange(3)]
        ghost = ghosts(roots, ~C.kinematic[rows], C.ghost[rows])
        C.ghost[rows] = ghost
        apply_commands(L, self.model, d, C, rows, self.dt, ghost)
        if d.ntree_awake == 0:  # every pool slot parked and no prop: nothing in MuJoCo can move
            self._ke = self._read = None
            return
        substeps = self.detail.substeps_for(self.model, L.num_ragdolls)
        reason = guarded_step(self.model, self.data, substeps, self._limit, self._owners)
        if reason is None:
            project_twist(self.layout, self.data)
        else:
            self.recoveries += 1
            warnings.warn(PhysicsRecovery(f"physics step undone, bodies reset: {reason}"), stacklevel=2)
        self._ke = self._read = None

    def _update_islands(self) -> None:
        """Put the ragdolls that need dynamics (or may touch what has them) in the model, and only those."""
        C = self.commands
        if self.simulate_animated:
            wanted = np.ones(len(C.keys), dtype=bool)
        else:
            needs = ~C.kinematic
            if self._held:
                needs[C.rows(sorted(self._held))] = True
            centres = self._centres()
            props = [self._prop_sphere(k) for k in sorted(self._props)]
            sources = np.concatenate([centres[needs], np.array([c for c, _ in props]).reshape(-1, 3)])
            source_radii = np.concatenate([C.reach[needs], [r for _, r in props]])
            inside = C.in_model
            wanted = needs.copy()
            near = near_simulated(centres[~needs], C.reach[~needs], sources, source_radii, inside[~needs])
            if near.any():  # the spheres hold any pose: the candidates' boxes in their poses decide
                cand = np.nonzero(~needs)[0][near]
                boxes = np.concatenate(
                    [
                        self._boxes(np.nonzero(needs)[0]),
                        np.array([[c - r, c + r] for c, r in props]).reshape(-1, 2, 3),
                    ]
                )
                near[near] = near_boxes(self._boxes(cand), boxes, inside[cand])
            wanted[~needs] = near
        changed = C.in_model != wanted
        if changed.any():
            C.in_model[changed] = wanted[changed]
            C.placed[changed] = False
            self._moved = True

    def _live(self, rows: I64) -> tuple[I64, I64]:
        """Which of ``rows`` (positions in ``rows``) are simulated where the model's state is current,
        and their ordinals in the layout."""
        C, L = self._cmds, self.layout
        if L is None or self.data is None or self._moved or not L.keys:
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
        live = np.nonzero(C.in_model[rows] & C.placed[rows])[0]
        return live, np.searchsorted(np.asarray(L.keys), C.keys[rows[live]])

    def _centres(self) -> _F:
        """Where every ragdoll's root is: simulated while in the model, else its commanded target."""
        C = self._cmds
        out = C.root.copy()
        live, ordinal = self._live(np.arange(len(C.keys)))
        if len(live):
            assert self.layout is not None and self.data is not None
            out[live] = self.data.qpos[self.layout.root_q[ordinal][:, None] + np.arange(3)]
        return out

    def _boxes(self, rows: I64) -> _F:
        """Boxes ``[n,2,3]`` around ragdolls ``rows`` in their current poses: a simulated one's from
        MuJoCo's geoms, an animated or newly joined one's from its command (:mod:`engine.ragdoll._bounds`)."""
        C = self._cmds
        out = np.empty((len(rows), 2, 3))
        live, ordinal = self._live(rows)
        keep = ~C.kinematic[rows[live]]
        live, ordinal = live[keep], ordinal[keep]
        L, m, d = self.layout, self.model, self.data
        if len(live) and L is not None and m is not None and d is not None:
            box_of = np.full(L.num_ragdolls, -1)
            box_of[ordinal] = np.arange(len(live))
            own = box_of[L.geom_owner]
            order = np.argsort(own, kind="stable")[np.count_nonzero(own < 0) :]
            out[live] = geom_boxes(m, d, L.geom[order], own[order], len(live))
        rest = np.ones(len(rows), dtype=bool)
        rest[live] = False
        if jit.enabled():  # every kind in one compiled pass
            r = rows[rest]
            slots = [self._ragdolls[k] for k in C.keys[r].tolist()]
            ix = np.array([self._kinds.of(s.kind, s.spec) for s in slots], dtype=np.int64)
            out[rest] = posed_boxes(self._kinds, ix, C.root[r], C.rot, C.starts[r])
            return out
        kinds: dict[bytes, list[int]] = {}
        for i in np.nonzero(rest)[0].tolist():
            kinds.setdefault(self._ragdolls[int(C.keys[rows[i]])].kind, []).append(i)
        for kind, idx in kinds.items():
            r = rows[idx]
            spec = self._ragdolls[int(C.keys[r[0]])].spec
            rot = C.rot[joint_rows(C.starts, r)].reshape(len(r), spec.skeleton.num_joints, 4)
            out[idx] = command_boxes(kind, spec, C.root[r], rot)
        return out

    def _prop_sphere(self, key: int) -> tuple[_F, float]:
        """A prop's bounding sphere over the next :data:`LOOKAHEAD` seconds."""
        ps = self._props[key]
        if ps.init is not None or self.data is None:
            pos, vel = (ps.init[0], ps.init[2]) if ps.init is not None else (np.zeros(3), np.zeros(6))
        else:
            pos, vel = self.data.qpos[ps.qadr : ps.qadr + 3], self.data.qvel[ps.dadr : ps.dadr + 3]
        return np.asarray(pos), ps.spec.radius + float(np.linalg.norm(vel[:3])) * LOOKAHEAD

    def mujoco_name(self, key: int, part: str) -> str:
        """MuJoCo's name of a part (joint name, ``<joint>_hold``, ``pin``…) of the pool slot lent to
        ragdoll ``key`` (slots are named by their place in the pool, not by the puppet)."""
        self.ensure_built()
        self._slot(key)
        pool = int(self.commands.pool[self.commands.row[key]])
        if pool < 0:
            raise KeyError(f"ragdoll {key} is not simulated now: it has no MuJoCo bodies")
        return rd_name(pool, part)

    def asleep(self) -> int:
        """How many pool slots are parked asleep (free, costing no dynamics)."""
        self.ensure_built()
        return 0 if self.data is None else int(np.count_nonzero(np.asarray(self.data.tree_asleep) >= 0))

    def in_model(self, key: int) -> bool:
        """Whether ragdoll ``key`` is simulated this step (animated ragdolls alone are not)."""
        self._slot(key)
        return bool(self.commands.in_model[self.commands.row[key]])

    # -- props ----------------------------------------------------------------------------
    def _prop(self, key: int) -> PropSlot:
        self.ensure_built()
        try:
            return self._props[key]
        except KeyError:
            raise KeyError(f"entity {key} is not a prop in the physics world") from None

    def prop_state(self, key: int) -> tuple[_F, _F, _F]:
        """Position ``[3]``, rotation ``[4]`` and velocity ``[6]`` (linear, angular) of a prop."""
        s = self._prop(key)
        d = self.data
        assert d is not None
        return (
            d.qpos[s.qadr : s.qadr + 3].copy(),
            d.qpos[s.qadr + 3 : s.qadr + 7].copy(),
            d.qvel[s.dadr : s.dadr + 6].copy(),
        )

    def prop_radius(self, key: int) -> float:
        """Current radius of a prop."""
        return self._prop(key).spec.radius

    def set_prop_radius(self, key: int, radius: float, mass: float) -> None:
        """Change a snowball's size and mass in place; a ball resting on the ground is lifted to stay on it."""
        if not (radius > 0 and mass > 0 and np.isfinite(radius) and np.isfinite(mass)):
            raise ValueError(f"prop radius and mass must be positive and finite, got {radius}, {mass}")
        s = self._prop(key)
        m, d = self.model, self.data
        assert m is not None and d is not None
        old = s.spec.radius
        s.spec = PropSpec(key, float(radius), float(mass), s.spec.friction)
        m.geom_size[s.geom, 0] = radius
        m.geom_rbound[s.geom] = radius
        m.geom_aabb[s.geom] = (0.0, 0.0, 0.0, radius, radius, radius)
        m.body_mass[s.body] = mass
        m.body_inertia[s.body] = 0.4 * mass * radius * radius
        # mj_setConst works in qpos0 on this data: keep the state around it
        state = np.empty(mujoco.mj_stateSize(m, _STATE))
        mujoco.mj_getState(m, d, state, _STATE)
        mujoco.mj_setConst(m, d)
        mujoco.mj_setState(m, d, state, _STATE)
        if d.qpos[s.qadr + 1] < old + 0.02 and radius > old:
            d.qpos[s.qadr + 1] += radius - old
        mujoco.mj_forward(m, d)
        self._ke = self._read = None

    def set_prop_kinematic(self, key: int, position: ArrayLike, rotation: ArrayLike, velocity: ArrayLike) -> None:
        """Place a prop where something else carries it (held by the stick), with its velocity."""
        s = self._prop(key)
        d = self.data
        assert d is not None
        pos = np.asarray(position, dtype=np.float64).reshape(3)
        vel = np.asarray(velocity, dtype=np.float64).reshape(6)
        if not (np.isfinite(pos).all() and np.isfinite(vel).all()):
            raise ValueError(f"prop {key}: pose or velocity has NaN or infinite values")
        d.qpos[s.qadr : s.qadr + 7] = np.concatenate([pos, quat.normalize(rotation)])
        d.qvel[s.dadr : s.dadr + 6] = vel

    # -- hashing --------------------------------------------------------------------------
    def state_bytes(self) -> bytes:
        """Every number that defines what the next step does: MuJoCo's integration state
        (time, qpos, qvel, act, warm start, ctrl, applied forces, active constraints, mocap
        poses), the model parameters we change at run time, the model's layout, and each
        ragdoll's pending command and last target."""
        self.ensure_built()
        m, d = self.model, self.data
        if m is None or d is None:
            return b"empty"
        state = np.empty(mujoco.mj_stateSize(m, _STATE))
        mujoco.mj_getState(m, d, state, _STATE)
        parts: list[bytes | np.ndarray] = [
            self._digest,
            state,
            m.actuator_gainprm[:, 0],
            m.actuator_biasprm[:, :3],
            m.eq_solref,
            m.geom_size[:, 0],
            m.body_mass,
            m.geom_contype,
        ]
        pooled = bool(self._pool.slots)
        if pooled:  # (a model of props alone hashes as it did before the pool)
            parts += [m.tree_sleep_policy, d.tree_asleep]
        C = self.commands
        for i in range(len(C.keys)):
            root, rot = C.pose(i)
            last = C.last(i)
            if pooled:
                parts.append(C.pool[i : i + 1])
            parts += [
                root,
                rot,
                np.array([C.muscle[i], C.pin[i], C.support[i], C.kinematic[i]]),
                C.hold_target[i],
                (C.hold[i] or "").encode(),
                b"L" if last is None else last[0].tobytes() + last[1].tobytes(),
            ]
        return b"".join(p if isinstance(p, bytes) else np.ascontiguousarray(p).tobytes() for p in parts)
