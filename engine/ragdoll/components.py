"""Per-entity ragdoll and prop components: only what changes each frame.

Modes follow PuppetMaster's vocabulary (research notes §2.2):

- ``ANIMATED`` — kinematic: the bodies are placed on the animated pose every step (with
  its velocity, so they push props); the output pose is the animation.
- ``ACTIVE`` — the muscles (servos) track the animated local rotations with
  ``muscle_weight``; the root is pinned to the animated root with ``pin_weight``; the
  output pose blends animation and simulation by ``blend_weight``.
- ``LIMP`` — dead: no muscles, no pin, the output pose is the simulation.

Switching mode only sets *targets*; the current weights ramp towards them at
``1 / transition_time`` per second, so every change of mode is smooth.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from engine.ragdoll.profile import RagdollProfile

__all__ = ["RagdollMode", "Ragdoll", "Prop", "SNOW_DENSITY"]

SNOW_DENSITY = 400.0  # kg/m³, packed snow


class RagdollMode(enum.Enum):
    """How a ragdoll relates to its animation."""

    ANIMATED = "animated"
    ACTIVE = "active"
    LIMP = "limp"


# mode -> (muscle, pin, blend) targets
_TARGETS = {
    RagdollMode.ANIMATED: (1.0, 1.0, 0.0),
    RagdollMode.ACTIVE: (1.0, 1.0, 1.0),
    RagdollMode.LIMP: (0.0, 0.0, 1.0),
}


def _vec3() -> NDArray[np.float64]:
    return np.zeros(3)


@dataclass
class Ragdoll:
    """A puppet's physical body and how strongly it follows its animation.

    Attributes:
        profile: the immutable asset (not hashed: it never changes during play).
        mode: see :class:`RagdollMode`; change it with :meth:`set_mode`.
        muscle_weight, pin_weight, blend_weight: current weights 0..1.
        muscle_target, pin_target, blend_target: where the weights are ramping to.
        transition_time: seconds for a weight to ramp from 0 to 1.
        held: joint held by the MotionStick (``"chest"``, ``"head"``) or ``None``.
        hold_target: world point the held body is pulled to by a spring.
        settled: the body has been still for ``still_frames`` ≥ the settle threshold.
        still_frames: consecutive frames below the settle thresholds.
        kinetic_energy: the body's kinetic energy after the last step (J).
    """

    profile: RagdollProfile = field(metadata={"hash": False})
    mode: RagdollMode = RagdollMode.ANIMATED
    muscle_weight: float = 1.0
    pin_weight: float = 1.0
    blend_weight: float = 0.0
    muscle_target: float = 1.0
    pin_target: float = 1.0
    blend_target: float = 0.0
    transition_time: float = 0.25
    held: str | None = None
    hold_target: NDArray[np.float64] = field(default_factory=_vec3)
    settled: bool = False
    still_frames: int = 0
    kinetic_energy: float = 0.0

    def set_mode(
        self,
        mode: RagdollMode,
        *,
        muscle: float | None = None,
        pin: float | None = None,
        blend: float | None = None,
        immediate: bool = False,
    ) -> None:
        """Switch mode; the weights ramp to the mode's targets (or the ones given).

        Args:
            mode: the new mode.
            muscle, pin, blend: override the mode's target weights (0..1).
            immediate: jump to the targets now instead of ramping.
        """
        m, p, b = _TARGETS[mode]
        targets = (
            _unit(m if muscle is None else muscle, "muscle"),
            _unit(p if pin is None else pin, "pin"),
            _unit(b if blend is None else blend, "blend"),
        )
        self.mode = mode
        self.muscle_target, self.pin_target, self.blend_target = targets
        if mode is not RagdollMode.LIMP:
            self.settled, self.still_frames = False, 0
        if immediate:
            self.muscle_weight, self.pin_weight, self.blend_weight = (
                self.muscle_target,
                self.pin_target,
                self.blend_target,
            )

    def ramp(self, dt: float) -> None:
        """Move every weight towards its target by ``dt / transition_time``."""
        step = 1.0 if self.transition_time <= 0 else dt / self.transition_time
        self.muscle_weight = _toward(self.muscle_weight, self.muscle_target, step)
        self.pin_weight = _toward(self.pin_weight, self.pin_target, step)
        self.blend_weight = _toward(self.blend_weight, self.blend_target, step)

    def grab(self, joint: str, target: NDArray[np.float64]) -> None:
        """Hold ``joint`` (one of ``profile.holdable``) by a spring at ``target``."""
        if joint not in self.profile.holdable:
            raise KeyError(f"joint {joint!r} is not holdable; holdable are {', '.join(self.profile.holdable)}")
        self.held = joint
        self.hold_target = np.asarray(target, dtype=np.float64).reshape(3).copy()

    def release(self) -> None:
        """Let go of the held body."""
        self.held = None


def _unit(value: float, name: str) -> float:
    if not 0.0 <= value <= 1.0:
        raise ValueError(f"{name} weight must be in 0..1, got {value}")
    return float(value)


def _toward(value: float, target: float, step: float) -> float:
    if abs(target - value) <= step:
        return target
    return value + step if target > value else value - step


@dataclass
class Prop:
    """A physical sphere (a snowball) whose pose lives in ``components.Transform``.

    Change ``radius`` at run time to grow it; with ``mass=None`` the mass follows the
    volume at ``density``. ``carried`` makes physics follow the Transform (the stick holds it)
    instead of writing it. ``placed`` hands a prop back to physics at its ``Transform`` with
    ``velocity`` for one step (set it when letting go, so the last carried velocity is not kept).
    """

    radius: float = 0.15
    mass: float | None = None
    density: float = SNOW_DENSITY
    friction: float = 1.0
    carried: bool = False
    velocity: NDArray[np.float64] = field(default_factory=lambda: np.zeros(6))
    placed: bool = False

    def current_mass(self) -> float:
        """The mass in use: the given one, or density × volume."""
        if self.mass is not None:
            return float(self.mass)
        return float(self.density * 4.0 / 3.0 * np.pi * self.radius**3)
