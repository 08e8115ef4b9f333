"""Blend lookup quality and speed on the puppet's Fig. 6.3 space (thesis §6.2.3).

Over a grid of requested (speed, hips height) inside the feasible set, each method
gives a blend point, which is then *played* (:func:`engine.blend.measure_locomotion`,
the runtime's stepping) and its root speed compared with the request:

- the IDW lookup (q = 7, k-d tree, probe slopes) against the naive linear mapping
  ``p_vel = u/u_max``, ``p_height`` linear in height — the non-linearity the thesis
  points out is the linear mapping's error;
- the thesis's plain IDW (no slopes) and scipy's LinearNDInterpolator and
  RBFInterpolator fitted on the same probes: speed error and time per query;
- foot sliding: the horizontal speed of a foot while it is in contact, over a few
  seconds of play at each of a dozen requests;
- one IDW query with thousands of probes, k-d tree against brute force;
- requests beyond the fastest blend, projected and sped up: the speed that plays.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.interpolate import LinearNDInterpolator, RBFInterpolator

from engine.blend import LookupTable, build_locomotion, foot_slide, measure_locomotion, play
from engine.blend.locomotion import LocomotionSet
from engine.blend.measure import blended_contacts
from puppetphone.bench.figures import Figure, median_time

__all__ = ["run", "request_grid", "linear_mapping"]

NAME = "blend"


def request_grid(loco: LocomotionSet, speeds: int = 30, heights: int = 15, min_speed: float = 0.2) -> np.ndarray:
    """Requests ``[R, 2]`` on a regular grid, kept where they lie inside the feasible set."""
    t = loco.table
    sp = np.linspace(min_speed, t.values[:, 0].max(), speeds)
    hs = np.linspace(t.values[:, 1].min(), t.values[:, 1].max(), heights)
    u = np.stack(np.meshgrid(sp, hs, indexing="ij"), axis=-1).reshape(-1, 2)
    assert t.feasible is not None
    inside = np.array([t.feasible.contains(t._scaled(x)) for x in u])
    return u[inside]


def linear_mapping(loco: LocomotionSet, u: np.ndarray) -> np.ndarray:
    """The naive map: speed over the run's speed, height linear between crouch and stand."""
    t = loco.table
    top_speed = t.values[:, 0].max()
    h = t.values[:, 1]
    p = np.stack([u[:, 0] / top_speed, (u[:, 1] - h.min()) / (h.max() - h.min())], axis=-1)
    return np.clip(p, 0.0, 1.0)


def _speed_error(loco: LocomotionSet, p: np.ndarray, u: np.ndarray) -> np.ndarray:
    played = measure_locomotion(loco.space, p)[:, 0]
    return 100.0 * np.abs(played / u[:, 0] - 1.0)


def _slide(
    loco: LocomotionSet, p: np.ndarray, u: np.ndarray | None, seconds: float = 3.0, dt: float = 1.0 / 60.0
) -> float:
    """Mean foot speed in contact (cm/s), the puppet carried at the requested speed ``u`` (or by root motion)."""
    from engine.clips import foot_contacts

    w = loco.space.weights(p)
    carried = None if u is None else np.stack([np.zeros(len(u)), np.zeros(len(u)), u[:, 0]], axis=-1)
    pb = play(loco.space, w, int(seconds / dt), dt, carried=carried)
    contacts = blended_contacts(loco.space, w[None], pb.phase, [foot_contacts(c) for c in loco.space.clips])
    return float(np.mean(foot_slide(loco.space, pb, contacts=contacts))) * 100.0


def run() -> list[Figure]:
    """All figures of the blend bench."""
    from engine.clips import default_clips

    clips = default_clips()
    t0 = time.perf_counter()
    loco = build_locomotion(clips, density=31)
    build_s = time.perf_counter() - t0
    table = loco.table
    u = request_grid(loco)
    figs: list[Figure] = []

    idw_err = _speed_error(loco, table.query(u), u)
    lin_err = _speed_error(loco, linear_mapping(loco, u), u)
    plain = LookupTable(table.probes, table.values, table.properties, table.grid_shape, gradients=False)
    plain_err = _speed_error(loco, plain.query(u), u)
    figs += [
        Figure(
            NAME,
            "speed_error_median_pct",
            float(np.median(idw_err)),
            "%",
            "linear mapping (straw man)",
            float(np.median(lin_err)),
        ),
        Figure(
            NAME, "speed_error_max_pct", float(idw_err.max()), "%", "linear mapping (straw man)", float(lin_err.max())
        ),
        Figure(
            NAME,
            "plain_idw_speed_error_median_pct",
            float(np.median(plain_err)),
            "%",
            "linear mapping (straw man)",
            float(np.median(lin_err)),
        ),
        Figure(
            NAME,
            "plain_idw_speed_error_max_pct",
            float(plain_err.max()),
            "%",
            "linear mapping (straw man)",
            float(lin_err.max()),
        ),
        Figure(NAME, "requests_inside", float(len(u)), "count"),
        Figure(NAME, "lookup_build_s", build_s, "s"),
    ]

    # Peers from scipy.interpolate on the same probes (in the table's scaled units).
    scaled = (table.values - table.offset) / table.scale
    xs = (u - table.offset) / table.scale
    lnd = LinearNDInterpolator(scaled, table.probes)
    rbf = RBFInterpolator(scaled, table.probes, kernel="thin_plate_spline", neighbors=32)
    p_lnd = np.asarray(lnd(xs))
    ok = np.isfinite(p_lnd).all(axis=-1)
    lnd_err = _speed_error(loco, np.clip(p_lnd[ok], 0, 1), u[ok])
    rbf_err = _speed_error(loco, np.clip(rbf(xs), 0, 1), u)
    one_u, one_x = u[len(u) // 2], xs[len(u) // 2][None]
    idw_one = median_time(lambda: table.query(one_u))
    figs += [
        Figure(
            NAME, "linear_nd_speed_error_median_pct", float(np.median(lnd_err)), "%", "idw", float(np.median(idw_err))
        ),
        Figure(NAME, "linear_nd_speed_error_max_pct", float(lnd_err.max()), "%", "idw", float(idw_err.max())),
        Figure(NAME, "rbf_speed_error_median_pct", float(np.median(rbf_err)), "%", "idw", float(np.median(idw_err))),
        Figure(NAME, "rbf_speed_error_max_pct", float(rbf_err.max()), "%", "idw", float(idw_err.max())),
        Figure(NAME, "linear_nd_query_us", median_time(lambda: lnd(one_x)) * 1e6, "us", "idw", idw_one * 1e6),
        Figure(NAME, "rbf_query_us", median_time(lambda: rbf(one_x)) * 1e6, "us", "idw", idw_one * 1e6),
    ]

    # Foot sliding over a dozen requests spread over the feasible set.
    pick = u[np.linspace(0, len(u) - 1, 12).astype(int)]
    figs.append(
        Figure(
            NAME,
            "foot_slide_cm_s",
            _slide(loco, table.query(pick), pick),
            "cm/s",
            "linear mapping (straw man)",
            _slide(loco, linear_mapping(loco, pick), pick),
        )
    )
    figs.append(Figure(NAME, "foot_slide_root_motion_cm_s", _slide(loco, table.query(pick), None), "cm/s"))
    figs.append(Figure(NAME, "foot_slide_clips_alone_cm_s", _slide(loco, loco.space.points, None), "cm/s"))

    # Beyond the fastest blend: projection plus speed-up.
    fastest = table.values[:, 0].max()
    run_height = float(table.values[np.argmax(table.values[:, 0]), 1])
    far = np.stack([np.linspace(1.2, 2.0, 5) * fastest, np.full(5, run_height)], axis=-1)
    errs = []
    for req in far:
        res = table.resolve(req)
        played = np.linalg.norm(loco.space.average_velocity(loco.space.weights(res.point))) * res.rate
        errs.append(100.0 * abs(played / req[0] - 1.0))
    figs.append(Figure(NAME, "outside_speed_error_max_pct", float(max(errs)), "%"))

    # One query with thousands of probes: k-d tree against brute force.
    big = build_locomotion(clips, density=64).table
    q = big.values[len(big.values) // 3] + 0.004
    figs.append(
        Figure(
            NAME,
            "lookup_us",
            median_time(lambda: big.query(q)) * 1e6,
            "us",
            f"brute force over {len(big.probes)} probes (straw man; the k-d tree peer: bench peers)",
            median_time(lambda: big.query_brute(q)) * 1e6,
        )
    )
    figs.append(Figure(NAME, "resolve_us", median_time(lambda: table.resolve(one_u)) * 1e6, "us"))
    figs += _runtime(loco)
    return figs


def _runtime(loco: LocomotionSet) -> list[Figure]:
    """The animation stage itself: one puppet and a hundred, each step (requests vary, so no memo hits)."""
    from engine.app import App
    from engine.blend import BlendLibrary, LocomotionPlayer, install_blend
    from engine.components import Puppet, Transform
    from engine.humanoid import humanoid_skeleton

    out = []
    for n in (1, 100):
        app = App(seed=0, plugins=[install_blend])
        app.world.resource(BlendLibrary).add("humanoid", loco)
        players = []
        for i in range(n):
            player = LocomotionPlayer(speed=0.3 + 0.02 * i)
            players.append(player)
            app.world.spawn(Transform(position=np.array([2.0 * i, 0.0, 0.0])), Puppet(humanoid_skeleton()), player)
        app.run_steps(3)
        tick = [0]

        def step(tick: list[int] = tick, players: list[LocomotionPlayer] = players, app: App = app) -> None:
            tick[0] += 1
            for j, p in enumerate(players):
                p.speed = 0.3 + 0.02 * j + 0.001 * (tick[0] % 50)
            app.step()

        per_step = median_time(step, repeats=7)
        out.append(Figure(NAME, f"animate_{n}_puppet{'s' if n > 1 else ''}_ms", per_step * 1e3, "ms"))
    return out
