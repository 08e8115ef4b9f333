"""The whole fall with the real puppet: held up, let go in mid-air, lands, settles, gets up.

This drives the puppet plugin of ``engine.statemachine.puppet`` (brain, locomotion, IK,
our physics, FK) with a MotionStick component only, as the snowman scene does.
"""

from __future__ import annotations

import numpy as np
import pytest

from engine.app import App
from engine.components import LocalPose, Stick
from engine.ragdoll import PhysicsWorld, Ragdoll, RagdollMode, max_rotation_jump

puppet = pytest.importorskip("engine.statemachine.puppet.plugin")


def test_let_go_in_mid_air_falls_settles_and_gets_up() -> None:
    from engine.statemachine.machine import Brain
    from engine.statemachine.puppet.body import GettingUp

    app = App(seed=0, plugins=[puppet.install_puppets])
    w = app.world
    e = puppet.spawn_puppet(w, (0.0, 0.0, 0.0))
    stick = w.get(w.spawn(Stick()), Stick)
    app.run_steps(10)
    stick.grabbed, stick.tip = e, np.array([0.0, 1.2, 0.0])
    trace: list[tuple[int, str]] = []
    getup_rot: list[np.ndarray] = []
    blend = None
    before = w.get(e, LocalPose).rotations.copy()
    lowest = np.inf
    pw = w.resource(PhysicsWorld)
    for i in range(800):
        if i < 90:
            stick.tip = np.array([0.0, 1.2 + 1.5 * min(i / 60, 1.0), 0.0])
        if i == 90:
            stick.grabbed = None
            held_chest_y = pw.body_positions(e)[2, 1]
        app.step()
        active = w.get(e, Brain).active
        if not trace or trace[-1][1] != active:
            trace.append((i, active))
        if active == "GetUp":
            if not getup_rot:
                getup_rot.append(before)  # the last limp frame: the blend must start from it
            getup_rot.append(w.get(e, LocalPose).rotations.copy())
            blend = w.get(e, GettingUp).blend or blend
        before = w.get(e, LocalPose).rotations.copy()
        if i >= 90 and active == "Ragdoll":
            lowest = min(lowest, float(pw.body_positions(e)[:, 1].min()))
        if trace[-1][1] != "GetUp" and len(trace) > 2 and trace[-2][1] == "GetUp":
            break
    states = [s for _, s in trace]
    assert "Ragdoll" in states and "GetUp" in states, trace
    assert held_chest_y > 2.0  # it was held up in the air by the chest
    assert lowest < 0.2  # it fell to the ground
    assert states[-1] != "Ragdoll" and states[-1] != "GetUp", trace
    rd = w.get(e, Ragdoll)
    assert rd.mode is RagdollMode.ANIMATED
    root = w.get(e, LocalPose).root
    assert root[1] == pytest.approx(0.94, abs=0.05)  # standing again
    jump = max_rotation_jump(np.stack(getup_rot))
    assert blend is not None and jump <= blend.clip_jump, (np.degrees(jump), np.degrees(blend.clip_jump))
