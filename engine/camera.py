"""Cameras as plain maths: view and projection matrices, pixel rays and projection.

No GL here, so input code (mouse picking through :meth:`ray`), tests and tools can use
a camera without a context. Conventions:

- World is Y up, metres. Matrices are numpy ``[4,4]`` float64 acting on column vectors
  (``clip = P @ V @ [x,y,z,1]``), the same values ``glm.lookAt`` / ``glm.perspective``
  give (OpenGL clip space, depth in ``[-1, 1]``). Upload them transposed (column-major).
- Pixels have their origin at the top-left corner of the image, ``x`` to the right and
  ``y`` down; ``(0, 0)`` is the corner, ``(w/2, h/2)`` the centre. :meth:`project` and
  :meth:`ray` are exact inverses of each other in this convention.

:class:`OrbitCamera` circles a target (the usual game/editor view, driven by the mouse);
:class:`PhoneCamera` looks out from a given eye with a given orientation (the "phone
view": what a phone held in the scene would see).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from engine import quat
from engine.arrays import F64 as F

__all__ = ["Camera", "OrbitCamera", "PhoneCamera", "look_at", "perspective"]

_UP = np.array([0.0, 1.0, 0.0])


def look_at(eye: ArrayLike, target: ArrayLike, up: ArrayLike = _UP) -> F:
    """Right-handed view matrix (camera looks down its -Z), as ``glm.lookAt``."""
    eye = np.asarray(eye, dtype=np.float64)
    f = np.asarray(target, dtype=np.float64) - eye
    f = f / np.linalg.norm(f)
    s = np.cross(f, np.asarray(up, dtype=np.float64))
    s = s / np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def perspective(fov_y_deg: float, aspect: float, near: float, far: float) -> F:
    """OpenGL perspective matrix (depth to ``[-1, 1]``), as ``glm.perspective``."""
    if not (near > 0 and far > near and aspect > 0 and 0 < fov_y_deg < 180):
        raise ValueError(f"bad projection: fov {fov_y_deg}, aspect {aspect}, near {near}, far {far}")
    t = 1.0 / math.tan(math.radians(fov_y_deg) / 2.0)
    m = np.zeros((4, 4))
    m[0, 0] = t / aspect
    m[1, 1] = t
    m[2, 2] = -(far + near) / (far - near)
    m[2, 3] = -2.0 * far * near / (far - near)
    m[3, 2] = -1.0
    return m


@dataclass
class Camera:
    """What every camera shares: a pinhole with a vertical field of view.

    Subclasses define :attr:`eye` and :attr:`rotation` (the camera-to-world rotation
    of a frame whose -Z is the view direction and +Y is up on screen).
    """

    fov_y: float = 50.0
    near: float = 0.05
    far: float = 200.0

    @property
    def eye(self) -> F:
        """Camera position ``[3]`` in world space."""
        raise NotImplementedError

    @property
    def rotation(self) -> F:
        """Camera-to-world rotation matrix ``[3,3]``: columns are right, up, backward."""
        raise NotImplementedError

    @property
    def forward(self) -> F:
        """Unit view direction ``[3]``."""
        return -self.rotation[:, 2]

    @property
    def right(self) -> F:
        """Unit screen-right direction ``[3]``."""
        return self.rotation[:, 0]

    @property
    def up(self) -> F:
        """Unit screen-up direction ``[3]``."""
        return self.rotation[:, 1]

    def view_matrix(self) -> F:
        """World-to-camera ``[4,4]``."""
        r = self.rotation
        m = np.eye(4)
        m[:3, :3] = r.T
        m[:3, 3] = -r.T @ self.eye
        return m

    def projection(self, aspect: float) -> F:
        """Camera-to-clip ``[4,4]`` for a viewport of ``width / height == aspect``."""
        return perspective(self.fov_y, aspect, self.near, self.far)

    def view_projection(self, aspect: float) -> F:
        """``projection(aspect) @ view_matrix()``."""
        return self.projection(aspect) @ self.view_matrix()

    def ray(self, px: float, py: float, width: int, height: int) -> tuple[F, F]:
        """World ray ``(origin [3], unit direction [3])`` through pixel ``(px, py)`` (top-left origin)."""
        if width <= 0 or height <= 0:
            raise ValueError(f"viewport must be positive, got {width}x{height}")
        if not (math.isfinite(px) and math.isfinite(py)):
            raise ValueError(f"pixel must be finite, got ({px}, {py})")
        t = math.tan(math.radians(self.fov_y) / 2.0)
        nx = 2.0 * px / width - 1.0
        ny = 1.0 - 2.0 * py / height
        r = self.rotation
        d = r @ np.array([nx * t * width / height, ny * t, -1.0])
        return self.eye.copy(), d / np.linalg.norm(d)

    def project(self, points: ArrayLike, width: int, height: int) -> F:
        """Pixel coordinates ``[N,2]`` (top-left origin) of world points ``[N,3]``.

        Points behind the camera come out as NaN, so callers cannot mistake them
        for on-screen positions.
        """
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        clip = np.c_[p, np.ones(len(p))] @ self.view_projection(width / height).T
        w = clip[:, 3]
        with np.errstate(divide="ignore", invalid="ignore"):
            ndc = clip[:, :2] / w[:, None]
        ndc[w <= 1e-9] = np.nan
        return np.c_[(ndc[:, 0] + 1.0) * 0.5 * width, (1.0 - ndc[:, 1]) * 0.5 * height]


@dataclass
class OrbitCamera(Camera):
    """A camera circling ``target`` at ``distance``.

    ``yaw`` (radians) turns about world Y; yaw 0 puts the eye on the +Z side looking
    towards -Z, i.e. facing a puppet in its rest pose. ``pitch`` (radians) raises the
    eye above the target and is clamped to ``[pitch_min, pitch_max]`` so the view
    never flips over the pole.

    The eye also stays at least ``clearance`` above ``ground`` (``None``: no floor), so
    orbiting low never puts the camera under the snow looking up through the ground
    plane: the pitch in use is never lower than the one that puts the eye there, and a
    pan cannot sink the target below the floor. :attr:`eye` and :attr:`rotation` apply
    the floor even when ``target`` or ``distance`` are assigned directly.
    """

    target: F = field(default_factory=lambda: np.array([0.0, 0.9, 0.0]))
    yaw: float = 0.0
    pitch: float = 0.3
    distance: float = 5.0
    pitch_min: float = -0.2
    pitch_max: float = 1.5
    distance_min: float = 0.3
    distance_max: float = 150.0
    ground: float | None = 0.0
    clearance: float = 0.1

    def __post_init__(self) -> None:
        self.target = np.asarray(self.target, dtype=np.float64).reshape(3).copy()
        self.pitch = float(np.clip(self.pitch, self.pitch_min, self.pitch_max))
        self.distance = float(np.clip(self.distance, self.distance_min, self.distance_max))
        self._keep_above_ground()

    @property
    def floor_pitch(self) -> float:
        """The lowest pitch that keeps the eye ``clearance`` above ``ground`` (``-pi/2`` without a floor)."""
        if self.ground is None:
            return -math.pi / 2
        s = (self.ground + self.clearance - float(self.target[1])) / self.distance
        return math.asin(min(max(s, -1.0), 1.0))

    @property
    def effective_pitch(self) -> float:
        """The pitch the view uses: ``pitch``, raised to :attr:`floor_pitch` if it is lower."""
        return max(self.pitch, self.floor_pitch)

    @property
    def eye(self) -> F:
        pitch = self.effective_pitch
        cp = math.cos(pitch)
        offset = np.array([cp * math.sin(self.yaw), math.sin(pitch), cp * math.cos(self.yaw)])
        return self.target + self.distance * offset

    @property
    def rotation(self) -> F:
        pitch = self.effective_pitch
        back = np.array([math.cos(pitch) * math.sin(self.yaw), math.sin(pitch), math.cos(pitch) * math.cos(self.yaw)])
        right = np.array([math.cos(self.yaw), 0.0, -math.sin(self.yaw)])
        up = np.cross(back, right)
        return np.stack([right, up, back], axis=1)

    def _keep_above_ground(self) -> None:
        """Lift the target onto the floor and the stored pitch to the floor's, so a drag
        back up answers at once instead of first climbing out of an invisible dead zone."""
        if self.ground is not None and self.target[1] < self.ground:
            self.target = np.array([self.target[0], self.ground, self.target[2]])
        self.pitch = self.effective_pitch

    def orbit(self, dyaw: float, dpitch: float) -> None:
        """Turn the eye around the target by ``dyaw``/``dpitch`` radians (pitch clamped, eye above the floor)."""
        self.yaw = float((self.yaw + dyaw + math.pi) % (2.0 * math.pi) - math.pi)
        self.pitch = float(np.clip(self.pitch + dpitch, self.pitch_min, self.pitch_max))
        self._keep_above_ground()

    def zoom(self, factor: float) -> None:
        """Multiply the distance by ``factor`` (> 1 moves away), clamped; the eye stays above the floor."""
        if not factor > 0:
            raise ValueError(f"zoom factor must be positive, got {factor}")
        self.distance = float(np.clip(self.distance * factor, self.distance_min, self.distance_max))
        self._keep_above_ground()

    def pan(self, dx: float, dy: float) -> None:
        """Move the target by ``dx`` along screen-right and ``dy`` along screen-up (metres), never below the floor."""
        r = self.rotation
        self.target = self.target + dx * r[:, 0] + dy * r[:, 1]
        self._keep_above_ground()


@dataclass
class PhoneCamera(Camera):
    """A first-person view from ``position`` with orientation ``orientation`` (w,x,y,z).

    The orientation maps the camera frame to the world; in the camera frame the view
    looks along -Z with +Y up, which is also the back camera of a phone in its own
    device frame (screen normal +Z). The identity therefore looks towards world -Z.
    """

    position: F = field(default_factory=lambda: np.array([0.0, 1.5, 4.0]))
    orientation: F = field(default_factory=lambda: quat.identity())
    fov_y: float = 60.0

    def __post_init__(self) -> None:
        self.position = np.asarray(self.position, dtype=np.float64).reshape(3).copy()
        self.orientation = quat.normalize(np.asarray(self.orientation, dtype=np.float64).reshape(4))

    @property
    def eye(self) -> F:
        return self.position

    @property
    def rotation(self) -> F:
        return quat.to_matrix(self.orientation)

    @classmethod
    def looking_at(cls, position: ArrayLike, target: ArrayLike, **kw: float) -> PhoneCamera:
        """A phone camera at ``position`` pointing at ``target`` with world Y up."""
        view = look_at(position, target)
        return cls(position=np.asarray(position, dtype=np.float64), orientation=quat.from_matrix(view[:3, :3].T), **kw)
