"""Phone attitude conventions turned into engine stick orientations.

Phones report attitude in a Z-up world (Android's rotation vector: X≈East, Y=North,
Z=up; CoreMotion's ``xArbitraryZVertical``: Z up, X arbitrary) and a device frame
with X right, Y towards the top edge, Z out of the screen (input-protocols §1.1–1.2).
The engine is Y up. The stick is held like a remote control: it points out of the
phone's top edge (device +Y) and its "up" is the screen normal (device +Z).

A stick orientation ``o`` is the rotation that takes the engine's +Z to the stick
direction (and +Y to the stick's up), so ``o = W · q_device · A`` with

- ``W``: phone world (Z up) → engine (Y up): ``(x, y, z) → (x, z, −y)``;
- ``A``: stick axes → device axes: +Z→+Y (top edge), +Y→+Z (screen normal).

ARKit (ZIG SIM 6-DoF) is already Y up; its camera looks along its −Z, so the stick
there is ``q_arkit · B`` with ``B`` a half turn about Y. The heading is arbitrary
in every case: tap-to-calibrate fixes it in the MotionStick.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from engine import quat

__all__ = [
    "WORLD_Z_UP_TO_ENGINE",
    "STICK_TO_DEVICE",
    "STICK_TO_ARKIT_CAMERA",
    "phone_to_stick",
    "arkit_to_stick",
    "z_up_to_engine",
    "tilt_from_gravity",
    "QUAT_ORDERS",
    "reorder_quat",
]

from engine.arrays import F64 as F

WORLD_Z_UP_TO_ENGINE: F = quat.from_axis_angle([1.0, 0.0, 0.0], -np.pi / 2)
STICK_TO_DEVICE: F = quat.from_axis_angle([0.0, 1.0, 1.0], np.pi)
STICK_TO_ARKIT_CAMERA: F = quat.from_axis_angle([0.0, 1.0, 0.0], np.pi)

QUAT_ORDERS = ("wxyz", "xyzw", "wzxy")


def reorder_quat(values: ArrayLike, order: str) -> F:
    """Scalar-first quaternion from four values sent in ``order`` (e.g. ``"xyzw"``)."""
    if sorted(order) != sorted("wxyz"):
        raise ValueError(f"quaternion order must be a permutation of 'wxyz', not {order!r}")
    v = np.asarray(values, dtype=np.float64)
    return np.array([v[order.index(c)] for c in "wxyz"])


def phone_to_stick(q_device: ArrayLike) -> F:
    """Stick orientation of a phone attitude given in a Z-up world (scalar first)."""
    return quat.normalize(quat.mul(quat.mul(WORLD_Z_UP_TO_ENGINE, q_device), STICK_TO_DEVICE))


def arkit_to_stick(q_camera: ArrayLike) -> F:
    """Stick orientation of an ARKit camera rotation (Y-up world; scalar first)."""
    return quat.normalize(quat.mul(q_camera, STICK_TO_ARKIT_CAMERA))


def z_up_to_engine(v: ArrayLike) -> F:
    """A vector of a Z-up world in engine axes (Y up)."""
    x, y, z = np.asarray(v, dtype=np.float64)
    return np.array([x, z, -y])


def tilt_from_gravity(up_device: ArrayLike) -> F:
    """Device attitude (Z-up world, no heading) from the "up" direction measured in the device.

    A phone lying flat measures up along its +Z; the rotation taking the measured up
    to world +Z is the device→world attitude up to an unknown heading.
    """
    u = np.asarray(up_device, dtype=np.float64)
    if np.linalg.norm(u) < 1e-6:
        return quat.identity()
    return quat.between(u, [0.0, 0.0, 1.0])
