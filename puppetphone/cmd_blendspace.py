"""``puppetphone blendspace``: inspect the puppet's blend space and its IDW lookup (thesis Fig. 6.3/6.4).

Without options it prints the clips and their points, the measured range of the
properties and the answer to a sample request. ``--plot PNG`` draws the lookup
graph as in Fig. 6.4: every probe at its measured (speed, hips height), coloured by
its velocity parameter (red channel, as in the thesis) and height parameter (green),
the feasible border, and a request outside with its projection and speed-up.
matplotlib is needed only for the plot (the ``plot`` extra).
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

__all__ = ["configure", "run", "draw_lookup"]


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the blendspace arguments."""
    parser.add_argument("--plot", metavar="PNG", help="draw the lookup graph (Fig. 6.4) to this PNG file")
    parser.add_argument("--density", type=int, default=31, help="probes per axis of the lookup grid (default 31)")
    parser.add_argument("--power", type=float, default=7.0, help="IDW power q (default 7)")
    parser.add_argument(
        "--query",
        nargs=2,
        type=float,
        metavar=("SPEED", "HEIGHT"),
        help="a request (m/s, hips height m) to resolve and mark; default: 1.3× the fastest blend at mid height",
    )


def draw_lookup(loco: Any, request: Any, path: str) -> None:
    """Render the lookup graph of ``loco`` with ``request`` and its resolution to ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.collections import LineCollection

    from engine.atomic import atomic_write_bytes

    table = loco.table
    res = table.resolve(request)
    colours = np.stack([table.probes[:, 0], table.probes[:, 1] * 0.6, np.full(len(table.probes), 0.25)], axis=-1)
    fig, ax = plt.subplots(figsize=(8, 6), dpi=110)
    ax.scatter(table.values[:, 0], table.values[:, 1], c=colours, s=14, zorder=2)
    if table.feasible is not None:
        seg = table.feasible.border_polyline() * table.scale + table.offset
        ax.add_collection(LineCollection(seg, colors="black", linewidths=1.6, zorder=3, label="feasible border"))
    for name, point in zip(loco.space.names, loco.space.points, strict=True):
        idx = int(np.argmin(np.linalg.norm(table.probes - point, axis=-1)))
        ax.annotate(name, table.values[idx], textcoords="offset points", xytext=(6, 6), fontsize=9, zorder=4)
    ax.plot(*request, marker="x", color="tab:blue", markersize=11, mew=2.5, ls="", zorder=5, label="request u")
    ax.plot(*res.feasible, marker="o", color="tab:green", markersize=9, ls="", zorder=5, label="projected u'")
    ax.annotate("", res.feasible, request, arrowprops={"arrowstyle": "->", "color": "tab:blue"}, zorder=4)
    ax.set_title(
        f"IDW lookup, q={table.power:g}, {len(table.probes)} probes — p=({res.point[0]:.2f}, {res.point[1]:.2f}), "
        f"speed-up ×{res.rate:.2f}",
        fontsize=10,
    )
    ax.set_xlabel("measured root speed u_vel (m/s)")
    ax.set_ylabel("measured hips height u_height (m)")
    ax.scatter([], [], c=[(1.0, 0.0, 0.25)], s=14, label="probe, red = p_vel, green = p_height")
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(alpha=0.3)
    ax.autoscale_view()
    ax.margins(x=0.08, y=0.05)
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png", bbox_inches="tight")
    plt.close(fig)
    atomic_write_bytes(path, buf.getvalue())


def run(args: argparse.Namespace) -> int:
    """Build the puppet's locomotion set, print it, and optionally plot the lookup graph."""
    import numpy as np

    from engine.blend import build_locomotion

    if args.density < 2:
        print("--density needs at least 2 probes per axis", file=sys.stderr)
        return 2
    if args.power <= 0:
        print("--power must be positive", file=sys.stderr)
        return 2
    if args.query is not None and not (np.isfinite(args.query).all() and args.query[0] >= 0):
        print("--query needs a non-negative speed and a finite height", file=sys.stderr)
        return 2
    try:
        from engine.clips import default_clips
    except ImportError as exc:
        print(f"the default clips are not available: {exc}", file=sys.stderr)
        return 1
    loco = build_locomotion(default_clips(), density=args.density, power=args.power)
    table = loco.table
    print("blend space (velocity, height):")
    for name, point in zip(loco.space.names, loco.space.points, strict=True):
        print(f"  {name:<12} p=({point[0]:.2f}, {point[1]:.2f})")
    lo, hi = table.values.min(axis=0), table.values.max(axis=0)
    print(f"probes: {len(table.probes)}; speed {lo[0]:.2f}–{hi[0]:.2f} m/s; hips height {lo[1]:.3f}–{hi[1]:.3f} m")
    if args.query is not None:
        request = np.array(args.query, dtype=np.float64)
    else:
        request = np.array([1.3 * hi[0], 0.5 * (lo[1] + hi[1])])
    res = table.resolve(request)
    where = "inside" if res.inside else f"outside -> projected to ({res.feasible[0]:.2f} m/s, {res.feasible[1]:.3f} m)"
    print(
        f"request ({request[0]:.2f} m/s, {request[1]:.3f} m): {where}; "
        f"p=({res.point[0]:.3f}, {res.point[1]:.3f}); speed-up x{res.rate:.3f}"
    )
    if args.plot:
        try:
            draw_lookup(loco, request, args.plot)
        except ImportError:
            print("plotting needs matplotlib: pip install 'puppetphone[plot]'", file=sys.stderr)
            return 1
        print(f"wrote {args.plot}")
    return 0
