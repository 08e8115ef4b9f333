"""The FK stage: turn every puppet's ``LocalPose`` into a ``WorldPose``, batched.

Puppets that share a hierarchy (the default humanoid, every snowman) are stacked
into one array and go through :func:`engine.fk.forward_kinematics` together, so a
hundred puppets cost one batched call per depth level, not a hundred FK passes.
The previous world pose is kept for render interpolation.

With numba (:mod:`engine.jit`) a crowd in its usual state costs no Python per puppet: the
grouping is made once per membership (an :class:`FKPlan`, remade when the ECS hands out a
new query result or a puppet's skeleton or offsets object changes), and when every pose is
in its column, at any rows (:meth:`engine.columns.Column.rows`: the group may be part of the
animation's batch; a pose replaced by other code, a fallen puppet's, is taken in), the compiled
kernel (:func:`engine.fk.fk_rows`, the arithmetic :func:`~engine.fk.forward_kinematics` runs)
writes the world poses into their columns in place, after the last step's are copied aside.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import repeat
from operator import attrgetter, is_
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from engine import jit
from engine.app import App
from engine.arrays import F64 as F
from engine.columns import Columns, Mark, assignment_mark, columns, unassigned_since
from engine.components import LocalPose, Puppet, WorldPose
from engine.ecs import Entity, World
from engine.fk import fk_rows, forward_kinematics
from engine.skeleton import Skeleton

__all__ = ["FKPlan", "fk_system", "install_fk"]

_PUPPET_FIELDS = ("skeleton", "offsets")
_PUPPET = attrgetter(*_PUPPET_FIELDS)


@dataclass
class _Group:
    """Puppets of one hierarchy, in entity order, with what their FK needs that does not change per step."""

    key: bytes
    skeleton: Skeleton
    entities: list[Entity]
    puppets: tuple[Puppet, ...]
    locals_: tuple[LocalPose, ...]
    offsets: F
    worlds: tuple[WorldPose, ...] = ()
    checked: tuple[NDArray[np.int64], ...] = ()  # the columns' row arrays last found to agree (_compiled)


@dataclass
class FKPlan:
    """Resource: the FK stage's grouping, kept while the world's queries return the same lists.

    ``table``/``posed`` are the query results it was made for (``(Puppet, LocalPose)`` and the
    same with ``WorldPose``; kept so their ids are not reused); ``puppets`` the table's ``Puppet``
    components and ``puppet_fields`` each one's ``(skeleton, offsets)`` objects then; ``marks`` where the assignment
    log of those two fields stood when the plan was last found to hold (:func:`_mark`)."""

    SIM_STATE: ClassVar[bool] = False
    table: list[tuple[Any, ...]] = field(default_factory=list)
    posed: list[tuple[Any, ...]] = field(default_factory=list)
    puppets: list[Puppet] = field(default_factory=list)
    puppet_fields: list[tuple[Any, ...]] = field(default_factory=list)
    groups: list[_Group] = field(default_factory=list)
    marks: Mark | None = None

    def holds(self, table: list[tuple[Any, ...]], posed: list[tuple[Any, ...]]) -> bool:
        """Whether the plan still describes these query results: at once while no puppet's skeleton or offsets
        was assigned since it last held, else by one C-level pass over the puppets."""
        if table is not self.table or posed is not self.posed or len(posed) != len(table):
            return False
        if unassigned_since(self.marks):
            return True
        try:
            holds = list(map(_PUPPET, self.puppets)) == self.puppet_fields
        except ValueError:  # an offsets array compared with another: it was replaced
            return False
        if holds:
            self.marks = _mark(self.puppets)
        return holds


def _mark(puppets: list[Puppet]) -> Mark | None:
    """Where the assignment log of the puppets' ``skeleton`` and ``offsets`` stands now
    (:func:`engine.columns.assignment_mark`); ``None`` for puppets of several classes (then every step compares them)."""
    kinds = set(map(type, puppets))
    return assignment_mark(kinds.pop(), _PUPPET_FIELDS) if len(kinds) == 1 else None


def _plan(table: list[tuple[Any, ...]], posed: list[tuple[Any, ...]]) -> FKPlan:
    """Group ``table``'s puppets by hierarchy; their world poses too if every puppet has one (``posed``)."""
    by_key: dict[bytes, list[tuple[Any, ...]]] = {}
    for row in table:
        by_key.setdefault(row[1].skeleton.parents.tobytes(), []).append(row)
    groups = []
    worlds = {row[0]: row[3] for row in posed} if len(posed) == len(table) else {}
    for key, rows in by_key.items():
        puppets = tuple(row[1] for row in rows)
        groups.append(
            _Group(
                key=key,
                skeleton=puppets[0].skeleton,
                entities=[row[0] for row in rows],
                puppets=puppets,
                locals_=tuple(row[2] for row in rows),
                offsets=np.array([p.joint_offsets() for p in puppets], dtype=np.float64),
                worlds=tuple(worlds[row[0]] for row in rows) if worlds else (),
            )
        )
    everyone = [row[1] for row in table]
    return FKPlan(table, posed, everyone, list(map(_PUPPET, everyone)), groups, _mark(everyone))


def _compiled(cols: Columns, group: _Group) -> bool:
    """FK of ``group`` straight into its world poses' columns; ``False`` (nothing done) unless every
    pose, local and world, is in its column (:meth:`~engine.columns.Column.rows`, at the same rows in
    the two local and in the four world columns) and the columns are C-contiguous doubles."""
    joints = group.skeleton.num_joints
    roots = cols.get(LocalPose, "root", joints).rows(group.locals_)
    rots = cols.get(LocalPose, "rotations", joints).rows(group.locals_)
    if roots is None or rots is None:
        return False
    worlds: list[tuple[NDArray[Any], NDArray[np.int64]]] = []
    for name in _WORLD_FIELDS:
        found = cols.get(WorldPose, name, joints).rows(group.worlds)
        if found is None:
            return False
        worlds.append(found)
    index = (roots[1], rots[1], *(found[1] for found in worlds))
    if not (len(index) == len(group.checked) and all(map(is_, index, group.checked))):
        # The same rows in the two local and in the four world columns (checked once while the
        # columns keep their rows: the row arrays stay the same objects).
        if not (np.array_equal(index[0], index[1]) and all(np.array_equal(index[2], i) for i in index[3:])):
            return False
        group.checked = index
    pos, rot, prev_pos, prev_rot = (found[0] for found in worlds)
    if not all(
        a.flags.c_contiguous and a.dtype == np.float64 for a in (roots[0], rots[0], pos, rot, prev_pos, prev_rot)
    ):
        return False
    fk_rows(
        group.skeleton.parents, roots[1], roots[0], rots[0], group.offsets, worlds[0][1], pos, rot, prev_pos, prev_rot
    )
    return True


_WORLD_FIELDS = ("positions", "rotations", "prev_positions", "prev_rotations")


def fk_system(world: World) -> None:
    """Compute world joint transforms for every puppet with a ``LocalPose``."""
    table = world.query(Puppet, LocalPose)
    posed = world.query(Puppet, LocalPose, WorldPose)
    plan = world.try_resource(FKPlan)
    if plan is None or not plan.holds(table, posed):
        plan = _plan(table, posed)
        world.insert_resource(plan)
    cols = columns(world)
    world_poses = world.components(WorldPose)
    for group in plan.groups:
        if group.worlds and jit.enabled() and _compiled(cols, group):
            continue
        skeleton = group.skeleton
        joints = skeleton.num_joints
        locals_ = group.locals_
        roots = cols.get(LocalPose, "root", joints).read(locals_)
        rots = cols.get(LocalPose, "rotations", joints).read(locals_)
        offsets = cols.stacked(("offsets", group.key))([p.joint_offsets() for p in group.puppets])
        pos, rot = forward_kinematics(skeleton, roots, rots, offsets)
        poses = [world_poses.get(e) for e in group.entities]
        if any(map(is_, poses, repeat(None))):  # a puppet's first pose
            for k, e in enumerate(group.entities):
                if poses[k] is None:
                    world.add(e, WorldPose(pos[k], rot[k], pos[k].copy(), rot[k].copy()))
            poses = [world_poses[e] for e in group.entities]
        # The previous step is kept for render interpolation: copied into its own columns, as
        # this step's values are written over the last step's in place.
        for name in ("positions", "rotations"):
            now = cols.get(WorldPose, name, joints)
            cols.get(WorldPose, f"prev_{name}", joints).write(poses, now.read(poses))
        cols.get(WorldPose, "positions", joints).write(poses, pos)
        cols.get(WorldPose, "rotations", joints).write(poses, rot)


def install_fk(app: App) -> None:
    """Plugin: the batched FK system in the ``fk`` stage."""
    app.add_system("fk", fk_system)
