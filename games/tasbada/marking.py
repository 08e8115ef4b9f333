"""Marking the real world (stage 1): drag a box or a lasso, move the floor line, press buttons.

One gesture is a press, a drag and a release of the MotionStick (mouse button or
phone touch). What it does is decided at the press: on a button it is a button press,
on the floor line's *handle* (a knob at the line's left end, :func:`on_ground_handle`)
it drags the line, anywhere else it draws — so a box may start right on the floor line
(where things stand) without grabbing it. Every set-up action (a mark, a move of the
floor line) is undoable, last first. A drawn path becomes a
*lasso* when it comes back near its start after going around (its length is well over
the half-perimeter of its bounding box); otherwise it is a *box* from the press to the
release point — so the same gesture serves a quick rectangle and a careful outline.

All coordinates are normalised image coordinates (:mod:`games.tasbada.view`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from games.tasbada.quest import Mark

__all__ = [
    "Button",
    "REAL_BUTTONS",
    "MENU_BUTTON",
    "MAX_MARKS",
    "MIN_SIZE",
    "GROUND_GRAB",
    "GROUND_HANDLE_U",
    "classify_path",
    "hit_button",
    "menu_buttons",
    "clamp_ground",
    "on_ground_handle",
]

MAX_MARKS = 4
MIN_SIZE = 0.025
"""Smallest mark side (fraction of the image): shorter drags are taken as slips."""
GROUND_GRAB = 0.035
"""The floor-line handle's radius (fraction of the image height)."""
GROUND_HANDLE_U = 0.04
"""Where the handle sits along the floor line (fraction of the image width): its left end."""
_ASPECT = 16.0 / 9.0


def on_ground_handle(p: NDArray[np.float64], ground_v: float) -> bool:
    """Whether a press at ``p`` takes the floor line's handle (a round knob, aspect-corrected)."""
    return bool(np.hypot((p[0] - GROUND_HANDLE_U) * _ASPECT, p[1] - ground_v) < GROUND_GRAB)


class Button:
    """A labelled rectangle ``(u0, v0, u1, v1)`` on the image that fires an ``action``."""

    __slots__ = ("action", "label", "rect")

    def __init__(self, action: str, label: str, rect: tuple[float, float, float, float]) -> None:
        self.action, self.label, self.rect = action, label, rect

    def contains(self, p: NDArray[np.float64]) -> bool:
        """Whether the pointer ``p`` is on the button."""
        u0, v0, u1, v1 = self.rect
        return bool(u0 <= p[0] <= u1 and v0 <= p[1] <= v1)

    def __repr__(self) -> str:
        return f"Button({self.action!r}, {self.label!r}, {self.rect})"


REAL_BUTTONS: tuple[Button, ...] = (
    Button("undo", "Undo", (0.66, 0.03, 0.80, 0.11)),
    Button("done", "Done", (0.82, 0.03, 0.97, 0.11)),
)
MENU_BUTTON = Button("menu", "Menu", (0.88, 0.89, 0.985, 0.97))


def menu_buttons(reached: list[str], startup: bool = False) -> list[Button]:
    """The restart menu: one button per reached stage, then a new journey and close.

    At startup (saved progress found) "close" continues at the furthest stage reached.
    """
    items = [(f"restart:{s}", f"Restart from: {s}") for s in reached]
    last = reached[-1] if reached else "real"
    items += [("restart:new", "New journey (forget the marks)"), ("close", f"Continue: {last}" if startup else "Back")]
    top, h, gap = 0.2, 0.085, 0.02
    return [
        Button(a, label, (0.3, top + i * (h + gap), 0.7, top + i * (h + gap) + h)) for i, (a, label) in enumerate(items)
    ]


def hit_button(buttons: tuple[Button, ...] | list[Button], p: NDArray[np.float64]) -> Button | None:
    """The first button under ``p``, if any."""
    for b in buttons:
        if b.contains(p):
            return b
    return None


def clamp_ground(v: float) -> float:
    """Keep the floor line where a floor can be (below the top fifth, above the bottom edge)."""
    return float(np.clip(v, 0.2, 0.95))


def classify_path(path: list[tuple[float, float]] | NDArray[np.float64]) -> Mark | None:
    """The mark a drawn path makes: a lasso, a box, or ``None`` for a slip too small to mean anything."""
    p = np.asarray(path, dtype=np.float64).reshape(-1, 2)
    if len(p) < 2:
        return None
    lo, hi = p.min(axis=0), p.max(axis=0)
    w, h = hi - lo
    if w < MIN_SIZE or h < MIN_SIZE:
        return None
    length = float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
    closure = float(np.linalg.norm(p[-1] - p[0]))
    if len(p) >= 8 and length > 1.2 * (w + h) and closure < 0.3 * float(np.hypot(w, h)):
        return Mark("lasso", p)
    return Mark("box", np.array([p[0], p[-1]]))
