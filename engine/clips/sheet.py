"""Contact sheets: stick figures of a few frames of each clip, side and front view, as a PNG.

A clip is judged by looking at it. This draws each clip as a strip of frames (left limbs
blue, right limbs red, ground contacts marked) so an animator can check knees, arm swing
and heel strikes at a glance. It is a development tool: matplotlib is imported only here.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from engine.clip import Clip
from engine.clips.contacts import foot_contacts, foot_sliding, sole_points, world_poses

__all__ = ["contact_sheet"]


def _segments(clip: Clip) -> list[tuple[int, int, str]]:
    sk = clip.skeleton
    out = []
    for j in range(1, sk.num_joints):
        name = sk.names[j]
        colour = "tab:blue" if name.startswith("l_") else "tab:red" if name.startswith("r_") else "0.2"
        out.append((int(sk.parents[j]), j, colour))
    return out


def contact_sheet(clips: Mapping[str, Clip], path: str | Path, frames: int = 8) -> Path:
    """Draw ``frames`` evenly spaced frames of every clip to ``path`` (PNG) and return the path.

    Left column: side view (Z forward to the right, Y up); right column: front view (the
    puppet's right on the picture's left). Each figure is drawn about its own root, so
    frames do not overlap; triangles under a foot mark frames where it is in contact. The
    title gives the measured ground speed and foot sliding.
    """
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle

    side_w, front_w = 1.0 * (frames - 1) + 1.6, 0.6 * (frames - 1) + 1.6
    fig = Figure(figsize=(1.25 * (side_w + front_w) + 0.5, 2.7 * len(clips)))
    axes = fig.subplots(len(clips), 2, gridspec_kw={"width_ratios": [side_w, front_w]}, squeeze=False)
    for row, (name, clip) in enumerate(clips.items()):
        pos, _ = world_poses(clip)
        soles = sole_points(clip)
        contact = foot_contacts(clip)
        head = clip.skeleton.index("head")
        feet = [clip.skeleton.index(n) for n in ("l_foot", "r_foot")]
        idx = np.linspace(0, clip.num_frames - 1, frames).round().astype(int)
        for col, (h, sign, gap) in enumerate(((2, 1.0, 1.0), (0, -1.0, 0.6))):
            ax = axes[row, col]
            for k, f in enumerate(idx):
                # Each figure is centred on its own root so frames never overlap; the ground
                # marks under it show where its feet are relative to the body.
                shift = gap * k - sign * pos[f, 0, h]
                p = pos[f]
                for a, b, c in _segments(clip):
                    ax.plot([sign * p[a, h] + shift, sign * p[b, h] + shift], [p[a, 1], p[b, 1]], color=c, lw=1.6)
                for s, c in ((0, "tab:blue"), (1, "tab:red")):
                    heel, toe = soles[f, s]
                    ax.plot(
                        [
                            sign * p[feet[s], h] + shift,
                            sign * heel[h] + shift,
                            sign * toe[h] + shift,
                            sign * p[feet[s], h] + shift,
                        ],
                        [p[feet[s], 1], heel[1], toe[1], p[feet[s], 1]],
                        color=c,
                        lw=1.2,
                    )
                    if contact[f, s]:
                        ax.plot(sign * 0.5 * (heel[h] + toe[h]) + shift, -0.04, marker="^", color=c, ms=5)
                ax.add_patch(Circle((sign * p[head, h] + shift, p[head, 1] + 0.1), 0.1, fill=False, color="0.2"))
                ax.text(gap * k, -0.16, f"{f}", fontsize=7, ha="center")
            ax.axhline(0.0, color="0.6", lw=0.8)
            ax.set_aspect("equal")
            ax.set_ylim(-0.2, 2.0)
            ax.set_xlim(-0.8, gap * (frames - 1) + 0.8)
            slide = foot_sliding(clip, contact)
            ax.set_title(
                f"{name} ({'side, facing right' if col == 0 else 'front'}): {clip.num_frames} frames @ "
                f"{clip.fps:g} fps, {clip.average_speed():.2f} m/s, foot sliding "
                f"{1000 * slide[0]:.1f}/{1000 * slide[1]:.1f} mm/s",
                fontsize=9,
            )
            ax.tick_params(labelsize=6)
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=90)
    return out
