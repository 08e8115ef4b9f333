"""The quest's simulation state: which stage, what was marked, which milestones are done.

Everything here is plain hashed data (a resource with ``SIM_STATE = True``), driven
only by ``world.frame * dt`` and the recorded input, so a replay reproduces it bit for
bit. The photo itself is *not* simulation state: marks are kept in normalised image
coordinates, so the same gestures over a different photo give the same quest.

The journey follows the reality–virtuality continuum of the thesis (Fig. 6.9):

``real`` → ``props alive`` → ``mixed`` → ``virtual``

with ``menu`` in front of it when saved progress offers a choice of where to restart.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

__all__ = ["STAGES", "MENU", "REAL", "PROPS_ALIVE", "MIXED", "VIRTUAL", "Mark", "Quest", "stage_index"]

REAL, PROPS_ALIVE, MIXED, VIRTUAL = "real", "props alive", "mixed", "virtual"
MENU = "menu"
STAGES: tuple[str, ...] = (REAL, PROPS_ALIVE, MIXED, VIRTUAL)


def stage_index(stage: str) -> int:
    """Position of ``stage`` along the continuum (``ValueError`` names the stages)."""
    if stage not in STAGES:
        raise ValueError(f"unknown stage {stage!r}; stages are {', '.join(STAGES)}")
    return STAGES.index(stage)


@dataclass
class Mark:
    """A real object the person marked: a box (two corners) or a lasso (a closed outline).

    ``points`` are normalised image coordinates ``[N,2]``; a box keeps its two corners.
    """

    kind: str
    points: NDArray[np.float64]

    def __post_init__(self) -> None:
        if self.kind not in ("box", "lasso"):
            raise ValueError(f"a mark is a 'box' or a 'lasso', not {self.kind!r}")
        p = np.asarray(self.points, dtype=np.float64).reshape(-1, 2)
        if len(p) < (2 if self.kind == "box" else 3) or not np.all(np.isfinite(p)):
            raise ValueError(f"a {self.kind} mark needs finite points, got {len(p)}")
        self.points = np.clip(p, 0.0, 1.0)

    @property
    def bbox(self) -> tuple[float, float, float, float]:
        """``(u0, v0, u1, v1)``: the smallest image rectangle holding the mark."""
        lo, hi = self.points.min(axis=0), self.points.max(axis=0)
        return float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])

    def to_json(self) -> dict[str, object]:
        """A JSON-ready form (for the save file)."""
        return {"kind": self.kind, "points": [[round(float(a), 6), round(float(b), 6)] for a, b in self.points]}

    @classmethod
    def from_json(cls, data: object) -> Mark:
        """The inverse of :meth:`to_json`; ``ValueError`` on anything malformed."""
        if not isinstance(data, dict) or "kind" not in data or "points" not in data:
            raise ValueError(f"not a mark: {data!r}")
        return cls(str(data["kind"]), np.asarray(data["points"], dtype=np.float64))


@dataclass
class Quest:
    """The whole quest state (a hashed resource).

    Times are simulation times (``world.time``) at which something began.
    """

    SIM_STATE: ClassVar[bool] = True

    stage: str = ""
    """The current stage; empty until the first step enters ``real`` (or ``menu``)."""
    stage_t: float = 0.0
    reached: list[str] = field(default_factory=list)
    marks: list[Mark] = field(default_factory=list)
    ground_v: float = 0.555
    """The floor line: the image row where the floor meets the back wall."""
    # Pointer and the gesture in progress.
    pointer: NDArray[np.float64] = field(default_factory=lambda: np.array([0.5, 0.5]))
    down: bool = False
    gesture: str = ""
    """What the current press does: ``draw`` a mark, drag the ``ground`` line, a ``button``."""
    path: list[tuple[float, float]] = field(default_factory=list)
    undo: list[list[str | float]] = field(default_factory=list)
    """Set-up actions to take back, last first: ``["mark", count after]`` or ``["ground", previous v]``."""
    alive_t: float = -1.0
    """When the props came alive (the narrator's clock), -1 before."""
    # Narration.
    line: int = -1
    line_t: float = 0.0
    script: str = ""
    """Which part of the narrator's script is being told (see :mod:`games.tasbada.narrator`)."""
    # Mixed stage.
    selfie_t: float = -1.0
    avatar: int | None = None
    freed: list[float] = field(default_factory=list)
    """Per creature: when it was freed, or -1 while caged."""
    crystals: list[float] = field(default_factory=list)
    """Per crystal: when it was gathered, or -1."""
    crystals_shown_t: float = -1.0
    gate_open_t: float = -1.0
    milestones: list[str] = field(default_factory=list)
    menu_open: bool = False
    saved_reached: list[str] = field(default_factory=list)
    pose: dict[str, list[float]] = field(default_factory=dict)
    """The player's keypoints (normalised selfie ``[x, y]`` by name, :mod:`games.tasbada.pose`):
    found in the selfie at set-up, or placed by hand with the pose picker; empty: none."""
    pose_aspect: float = 1.0
    """Width / height of the picture the keypoints are measured on."""
    pose_picker: bool = False
    """No pose came from the selfie: stage 2 shows the pose picker (:mod:`games.tasbada.picker`)."""
    """Stages reached in an earlier session (from the save file), offered by the menu."""

    def time_in_stage(self, now: float) -> float:
        """Seconds since the current stage began."""
        return now - self.stage_t
