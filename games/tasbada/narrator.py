"""The narrator: what it says, when, and how its cut-out moves (thesis §6.4, Fig. 6.11).

Timing is a pure function of simulation time, so the narration replays exactly: each
line stays up for a time that grows with its length (about a reading pace), and a
touch skips ahead. The cut-out's motion is a small set of numbers per frame — hop
height, squash/stretch, mouth opening, blink, gaze — that the compositor turns into
pixels; a hop stretches the body on the way up and squashes it on landing, keeping
the area roughly constant (the classic squash-and-stretch rule).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["SCRIPTS", "line_duration", "script_line", "PropMotion", "prop_motion"]

SCRIPTS: dict[str, tuple[str, ...]] = {
    "wake": (
        "Oh! Hello there... you woke me up!",
        "I have watched over this room for years.",
        "Behind that wall lies Tasbada, a world of crystal and light.",
        "Its gate is locked, and three little creatures are caged.",
        "Free them, gather the crystals, and the gate will open.",
        "But first, let me see you! Look into the camera...",
    ),
    "selfie": ("Three...", "Two...", "One... smile!", "Got you! Here is your avatar."),
    "mixed": ("Grab your avatar and walk it to the cages!",),
    "freed": ("One free! Two more to go.", "Another one! Just one cage left."),
    "crystals": ("All free! Look, crystals are sprouting. Gather them all!",),
    "gate": ("The gate is glowing... walk through it!",),
    "virtual": ("Welcome to Tasbada! It is all yours. Explore!",),
}
SELFIE_BEAT = 1.0
"""Seconds per countdown line of the selfie."""


def line_duration(text: str) -> float:
    """How long a line stays up: a base plus a reading pace (about 18 characters a second)."""
    return 1.6 + 0.055 * len(text)


def script_line(script: str, index: int) -> str:
    """Line ``index`` of ``script`` ('' past the end or for no script)."""
    lines = SCRIPTS.get(script, ())
    return lines[index] if 0 <= index < len(lines) else ""


@dataclass(frozen=True)
class PropMotion:
    """One frame of an animated prop, in image units (fractions of the image height).

    ``hop`` lifts the prop; ``sx``/``sy`` scale it about its base; ``mouth`` in [0,1]
    opens the mouth; ``blink`` in [0,1] closes the eyes; ``gaze`` in [-1,1] turns the eyes;
    ``lean`` shears it sideways (image units of sideways shift per unit of height).
    """

    hop: float
    sx: float
    sy: float
    mouth: float
    blink: float
    gaze: float
    lean: float = 0.0


def prop_motion(
    t: float, phase: float = 0.0, talking: bool = False, energy: float = 1.0, gaze: float = 0.0
) -> PropMotion:
    """The motion of a prop alive for ``t`` seconds.

    Args:
        t: seconds since the prop came alive (negative: not yet, it stands still).
        phase: offset in seconds so several props do not bounce in step.
        talking: whether the mouth moves.
        energy: 1 for the bouncing idle; larger for the wake-up leap.
        gaze: where the eyes look, -1 left to 1 right.
    """
    if t < 0:
        return PropMotion(0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0)
    period = 0.9 if talking else 1.25
    s = ((t + phase) / period) % 1.0
    hop = 0.035 * energy * math.sin(math.pi * s) ** 1.5
    # Squash at contact (s near 0 or 1), stretch at take-off and landing speeds.
    contact = max(0.0, 1.0 - min(s, 1.0 - s) / 0.12)
    speed = abs(math.cos(math.pi * s))
    sy = 1.0 - 0.10 * energy * contact + 0.06 * energy * speed * (1.0 - contact)
    sx = 1.0 / math.sqrt(max(sy, 0.5))
    if talking:
        mouth = 0.5 + 0.5 * math.sin(2.0 * math.pi * 4.2 * t) * math.sin(2.0 * math.pi * 0.9 * t + 0.6)
        mouth = min(max(mouth, 0.0), 1.0)
    else:
        mouth = 0.0
    beat = (t + 0.37 * phase) % 3.3
    blink = max(0.0, 1.0 - abs(beat - 0.08) / 0.08) if beat < 0.16 else 0.0
    # Lean into the jump on the way up, back on the way down, and a little towards what it looks at.
    lean = 0.07 * energy * math.sin(2.0 * math.pi * s) + 0.04 * max(-1.0, min(1.0, gaze))
    return PropMotion(hop, sx, sy, mouth, blink, max(-1.0, min(1.0, gaze)), lean)
