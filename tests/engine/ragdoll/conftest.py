"""Fixtures for the ragdoll tests: the humanoid, a walk, get-up clips and a physics app.

The walk and get-up clips come from ``engine.clips.default_clips()`` when that library
provides them; until then small synthetic ones with the same shape stand in.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from engine import quat
from engine.app import App
from engine.clip import Clip
from engine.components import LocalPose, Puppet
from engine.humanoid import humanoid_skeleton
from engine.ragdoll import Ragdoll, RagdollMode, default_profile, install_physics
from engine.skeleton import Skeleton

X = np.array([1.0, 0.0, 0.0])


def _library() -> dict[str, Clip]:
    try:
        from engine.clips import default_clips  # type: ignore[import-not-found]
    except ImportError:
        return {}
    return dict(default_clips())


@pytest.fixture(scope="session")
def skeleton() -> Skeleton:
    return humanoid_skeleton()


def synthetic_walk(sk: Skeleton, fps: float = 60.0, period: float = 1.1, height: float = 1.25) -> Clip:
    """A swinging walk cycle: hips ±26°, knees 0..29°, arms ±20°, a little spine turn."""
    t = np.arange(int(round(period * fps))) / fps
    ph = 2 * np.pi * t / period
    s = np.sin(ph)
    rot = quat.identity(len(t), sk.num_joints)

    def put(name: str, axis: np.ndarray, ang: np.ndarray) -> None:
        rot[:, sk.index(name)] = quat.from_axis_angle(np.broadcast_to(axis, (len(t), 3)), ang)

    put("l_upper_leg", X, -0.45 * s)
    put("r_upper_leg", X, 0.45 * s)
    put("l_lower_leg", X, 0.5 * np.maximum(0, np.sin(ph + 1.2)))
    put("r_lower_leg", X, 0.5 * np.maximum(0, np.sin(ph + 1.2 + np.pi)))
    put("l_upper_arm", X, 0.35 * s)
    put("r_upper_arm", X, -0.35 * s)
    put("l_lower_arm", X, np.full(len(t), -0.3))
    put("r_lower_arm", X, np.full(len(t), -0.3))
    put("spine", np.array([0.0, 1.0, 0.0]), 0.1 * s)
    root = np.stack([np.zeros_like(t), height + 0.02 * np.cos(2 * ph), np.zeros_like(t)], axis=1)
    return Clip("walk", sk, fps, root, rot, loop=True)


def synthetic_get_up(sk: Skeleton, face_up: bool, fps: float = 60.0, seconds: float = 1.5) -> Clip:
    """Lying (on the back or the front) to standing in the rest (idle) pose."""
    n = int(round(seconds * fps)) + 1
    a = np.linspace(0.0, 1.0, n)
    s = a * a * (3 - 2 * a)
    lie = quat.from_axis_angle(X, -np.pi / 2 if face_up else np.pi / 2)
    rot = quat.identity(n, sk.num_joints)
    rot[:, 0] = quat.slerp(lie, quat.identity(), s)
    bend = np.sin(np.pi * s) * 1.4
    for side in ("l", "r"):
        rot[:, sk.index(f"{side}_upper_leg")] = quat.from_axis_angle(np.broadcast_to(X, (n, 3)), -bend)
        rot[:, sk.index(f"{side}_lower_leg")] = quat.from_axis_angle(np.broadcast_to(X, (n, 3)), 1.6 * bend)
    root = np.stack([np.zeros(n), 0.15 + 0.8 * s, np.zeros(n)], axis=1)
    return Clip("get_up_face_up" if face_up else "get_up_face_down", sk, fps, root, rot)


@pytest.fixture(scope="session")
def walk_clip(skeleton: Skeleton) -> Clip:
    lib = _library()
    return lib["walk"] if "walk" in lib else synthetic_walk(skeleton)


@pytest.fixture(scope="session")
def get_up_clips(skeleton: Skeleton) -> dict[str, Clip]:
    lib = {k: v for k, v in _library().items() if k.startswith("get_up")}
    return lib or {
        "get_up_face_up": synthetic_get_up(skeleton, True),
        "get_up_face_down": synthetic_get_up(skeleton, False),
    }


@pytest.fixture
def make_app(skeleton: Skeleton) -> Callable[..., tuple[App, int]]:
    """An app with physics and one puppet ragdoll in the given pose and mode."""

    def make(
        root: np.ndarray | None = None,
        rotations: np.ndarray | None = None,
        mode: RagdollMode = RagdollMode.LIMP,
        seed: int = 0,
    ) -> tuple[App, int]:
        app = App(seed=seed, plugins=[install_physics])
        rd = Ragdoll(default_profile(skeleton))
        rd.set_mode(mode, immediate=True)
        r = np.array([0.0, 1.95, 0.0]) if root is None else np.asarray(root, dtype=np.float64)
        q = quat.identity(skeleton.num_joints) if rotations is None else np.asarray(rotations)
        e = app.world.spawn(Puppet(skeleton), LocalPose(r.copy(), q.copy()), rd)
        return app, e

    return make


@pytest.fixture(scope="session")
def idle_rotations(skeleton: Skeleton) -> np.ndarray:
    """The idle pose's local rotations: the library's idle clip, else the rest pose."""
    lib = _library()
    return lib["idle"].sample(0.0).rotations if "idle" in lib else quat.identity(skeleton.num_joints)
