"""Ragdoll benchmark: the physics stage's cost per 60 Hz step for 1 and 10 active ragdolls.

Each active ragdoll tracks a walk (the library's ``walk`` clip, or a swinging stand-in
when the clip library is absent) with muscle and pin weight 1, on the ground. The
baseline is the same number of *limp* ragdolls in the same kind of world, so the ratio
is what muscles and pins cost (PuppetMaster quotes "1 puppet ≈ 2 normal ragdolls").
Also reported: the cost of adding an eleventh to fifteenth ragdoll at run time, in thread CPU
time (the pool grows in chunks of :data:`engine.ragdoll._pool.CHUNK` slots, so most joins take a
free slot and only a chunk's first compiles the model again: ``ragdoll_add_rebuilds`` counts those
compiles), and the active ragdoll's mean joint tracking error.
"""

from __future__ import annotations

import time

import numpy as np

from engine import quat
from engine.app import App
from engine.clip import Clip
from engine.components import LocalPose, Puppet
from engine.ecs import World
from engine.humanoid import humanoid_skeleton
from engine.ragdoll import PhysicsWorld, Ragdoll, RagdollMode, default_profile, install_physics
from puppetphone.bench.figures import Figure, median_time

__all__ = ["run"]

BENCH = "ragdoll"


def _walk() -> Clip:
    try:
        from engine.clips import default_clips

        return default_clips()["walk"]
    except (ImportError, KeyError):
        sk = humanoid_skeleton()
        t = np.arange(66) / 60.0
        s = np.sin(2 * np.pi * t / 1.1)
        rot = quat.identity(len(t), sk.num_joints)
        x = np.broadcast_to([1.0, 0.0, 0.0], (len(t), 3))
        for name, amp in (("l_upper_leg", -0.45), ("r_upper_leg", 0.45), ("l_upper_arm", 0.35), ("r_upper_arm", -0.35)):
            rot[:, sk.index(name)] = quat.from_axis_angle(x, amp * s)
        root = np.stack([np.zeros_like(t), np.full_like(t, 0.95), np.zeros_like(t)], axis=1)
        return Clip("walk", sk, 60.0, root, rot, loop=True)


def _app(n: int, mode: RagdollMode, clip: Clip) -> tuple[App, list[int]]:
    app = App(seed=0, plugins=[install_physics])
    sk = clip.skeleton
    profile = default_profile(sk)
    ents = []
    for i in range(n):
        p = clip.sample(0.0)
        rd = Ragdoll(profile)
        rd.set_mode(mode, immediate=True)
        ents.append(app.world.spawn(Puppet(sk), LocalPose(p.root + [2.0 * i, 0.0, 0.0], p.rotations.copy()), rd))

    def animate(world: World) -> None:
        p = clip.sample(world.time)
        for i, e in enumerate(ents):
            lp = world.get(e, LocalPose)
            lp.root, lp.rotations = p.root + [2.0 * i, 0.0, 0.0], p.rotations

    app.add_system("animation", animate)
    app.run_steps(30)  # past the first contacts and ramps
    return app, ents


def _tracking_error(clip: Clip) -> float:
    app, (e,) = _app(1, RagdollMode.ACTIVE, clip)
    pw = app.world.resource(PhysicsWorld)
    errs = []
    for _ in range(120):
        app.step()
        target = clip.sample(app.world.time - app.world.dt)
        errs.append(np.degrees(quat.angle_between(pw.pose(e).rotations, target.rotations)).mean())
    return float(np.mean(errs))


def run() -> list[Figure]:
    """Measure and return the ragdoll figures."""
    clip = _walk()
    figures = []
    for n in (1, 10):
        active, _ = _app(n, RagdollMode.ACTIVE, clip)
        limp, _ = _app(n, RagdollMode.LIMP, clip)
        t_active = median_time(active.step, repeats=9, min_time=0.1) * 1e3
        t_limp = median_time(limp.step, repeats=9, min_time=0.1) * 1e3
        figures.append(Figure(BENCH, f"ragdoll_step_ms_{n}", t_active, "ms", f"{n} limp ragdoll(s)", t_limp))
    app, ents = _app(10, RagdollMode.ACTIVE, clip)
    pw = app.world.resource(PhysicsWorld)
    rebuilds_before, rebuild = pw.rebuilds, []
    for k in range(5):
        p = clip.sample(0.0)
        rd = Ragdoll(default_profile(clip.skeleton))
        app.world.spawn(Puppet(clip.skeleton), LocalPose(p.root + [-2.0 * (k + 1), 0.0, 0.0], p.rotations.copy()), rd)
        t0 = time.thread_time()
        app.step()
        rebuild.append(time.thread_time() - t0)
    figures.append(
        Figure(
            BENCH,
            "ragdoll_add_ms",
            float(np.median(rebuild)) * 1e3,
            "ms",
            "one step of 10 active ragdolls",
            figures[-1].value,
        )
    )
    figures.append(Figure(BENCH, "ragdoll_add_rebuilds", float(pw.rebuilds - rebuilds_before), "count"))
    figures.append(Figure(BENCH, "ragdoll_track_error_deg", _tracking_error(clip), "deg"))
    return figures
