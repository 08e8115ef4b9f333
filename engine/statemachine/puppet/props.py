"""Props held by the MotionStick: a grabbed ball hangs at the stick's tip.

While a stick holds a prop, physics follows the prop (``Prop.carried``) and the
prop goes where the stick wants its anchor, never below the ground; released, it
keeps the stick's velocity and physics takes it again — so a ball can be lifted
onto another one, or thrown.
"""

from __future__ import annotations

import numpy as np

from engine.components import Grabbable, Stick, Transform
from engine.ecs import World
from engine.ragdoll.components import Prop
from engine.statemachine.puppet.senses import wanted_anchor

__all__ = ["held_props_system"]


#: Gap kept between a held ball and the balls it passes (m): at contact distance a moving kinematic
#: ball shoves the other one (a low carry plowed a big ball metres aside).
CLEARANCE = 0.03


def _clear_of_others(point: np.ndarray, entity: int, radius: float, props: list) -> np.ndarray:
    """Keep a held ball out of the ground and out of every other ball: it passes over them.

    A held ball is moved kinematically; letting it sink into another would hand the
    physics an unresolvable overlap, and pushing it around the other's side shoves that
    one along. Where the two would overlap the held ball rises to ride over the other's
    top (its ground position is the stick's), ``CLEARANCE`` above its surface.
    """
    p = np.array(point, dtype=np.float64)
    for _ in range(3):
        p[1] = max(p[1], radius)
        for e, other, otr in props:
            if e == entity:
                continue
            need = radius + other.radius + CLEARANCE
            d = p - otr.position
            if float(np.linalg.norm(d)) >= need:
                continue
            across = float(np.hypot(d[0], d[2]))
            p[1] = otr.position[1] + np.sqrt(max(need * need - across * across, 0.0))
    return p


def held_props_system(world: World) -> None:
    """The ``statemachine`` stage: move held props with their sticks; let go on release."""
    holders = {s.grabbed: s for _, s in world.query(Stick) if s.grabbed is not None}
    released = {s.released for _, s in world.query(Stick) if s.released is not None}
    props = world.query(Prop, Transform)
    for e, prop, tr, grab in world.query(Prop, Transform, Grabbable):
        stick = holders.get(e)
        if stick is not None:
            anchor = _clear_of_others(wanted_anchor(stick), e, prop.radius, props)
            velocity = (anchor - tr.position) / world.dt
            tr.position = anchor
            prop.carried = True
            prop.velocity = np.concatenate([velocity, np.zeros(3)])
            grab.radius = prop.radius
        elif prop.carried and e in released:
            prop.carried, prop.placed = False, True  # thrown: it keeps the stick's velocity
