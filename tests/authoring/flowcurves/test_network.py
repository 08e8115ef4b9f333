"""The centre-point network (Eq. 3.7–3.8): every curve ends up pointing at the centre-point."""

from __future__ import annotations

import math

import numpy as np

from authoring.flowcurves.network import FlowNetwork, average_curves, tip_angle


def _posts(xs: tuple[float, ...], lean: float = 0.0) -> list[np.ndarray]:
    return [np.c_[np.linspace(x, x + lean, 20), np.linspace(500.0, 300.0, 20)] for x in xs]


def test_every_curve_converges_on_the_centre_point() -> None:
    net = FlowNetwork.build(_posts((200.0, 420.0, 860.0, 1080.0)), [640.0, 100.0], 1280)
    assert len(net.curves) == 4
    for curve in net.curves:
        assert math.degrees(tip_angle(curve, net.centre)) < 3.0
        # kept end: the far one (bottom, y = 500), tangent unchanged
        assert abs(curve(0.0)[0][1] - 500.0) < 2.0
    before = [math.degrees(tip_angle(a, net.centre)) for a in net.averages]
    assert max(before) > 20.0  # they did not point there to begin with


def test_dragging_the_centre_point_rebends_live() -> None:
    net = FlowNetwork.build(_posts((200.0, 1080.0)), [640.0, 100.0], 1280)
    for point in ([700.0, 150.0], [500.0, 80.0], [900.0, 200.0]):
        net.move(point, warm=True)
        assert all(math.degrees(tip_angle(c, net.centre)) < 3.0 for c in net.curves)


def test_curves_close_together_are_averaged_into_one() -> None:
    """Eq. 3.7 extends each curve along its neighbours: two posts 30 px apart make one flow curve,
    posts far apart (beyond d_Max) stay two."""
    assert len(average_curves(_posts((400.0, 430.0)), 1280, d_max=60.0)) == 1
    assert len(average_curves(_posts((200.0, 1000.0)), 1280, d_max=60.0)) == 2


def test_a_warm_drag_converges_on_the_new_point_as_well_as_a_cold_build() -> None:
    """Each drag step re-bends from the last step's curves (a few Newton steps, all curves in
    one batch); the curves must point at the new centre-point within the cold build's bound
    (3°, as above) and reach the cold build's minimum of Eq. 3.8, not stop short of it."""
    posts = _posts((200.0, 420.0, 860.0, 1080.0), lean=15.0)
    net = FlowNetwork.build(posts, [640.0, 100.0], 1280)
    for k in range(1, 9):
        point = [640.0 + 12.0 * k, 100.0 + 4.0 * k]
        net.move(point, warm=True)
        cold = FlowNetwork.build(posts, point, 1280)
        assert len(net.curves) == len(cold.curves) == 4
        for warm_curve, cold_curve in zip(net.curves, cold.curves):
            assert math.degrees(tip_angle(warm_curve, point)) < 3.0
            assert math.degrees(tip_angle(cold_curve, point)) < 3.0
            assert np.abs(warm_curve.sample(32) - cold_curve.sample(32)).max() < 1.0  # the same curve, px


def test_the_warm_start_really_moves_the_curves() -> None:
    """A drag far enough that the previous curves miss the new point by far more than the bound."""
    net = FlowNetwork.build(_posts((200.0, 1080.0)), [640.0, 100.0], 1280)
    before = [c.q.copy() for c in net.curves]
    net.move([400.0, 250.0], warm=True)
    assert all(math.degrees(tip_angle(c, [400.0, 250.0])) < 3.0 for c in net.curves)
    assert max(np.abs(c.q - q).max() for c, q in zip(net.curves, before)) > 10.0


def test_the_bend_energy_gradient_is_exact() -> None:
    """The drag's Newton steps rely on the analytic gradient of Eq. 3.8: central differences agree."""
    from authoring.flowcurves.hermite import Hermite
    from authoring.flowcurves.network import _free_of, _problem

    rng = np.random.default_rng(3)
    for n in (2, 3, 5):
        curve = Hermite.line([100.0, 500.0], [130.0, 300.0], n)
        energy = _problem([curve], [640.0, 100.0])
        x = _free_of(curve) + rng.normal(0.0, 20.0, 4 * n - 4)
        _, g = energy(x)
        h = 1e-5
        steps = np.eye(len(x)) * h
        fd = (energy.batch((x + steps)[None])[0] - energy.batch((x - steps)[None])[0]) / (2 * h)
        assert np.abs(fd - g).max() < 1e-6 * max(1.0, np.abs(fd).max())
