"""The controller as camera: a device stick's view looks along the stick from its pivot; the mouse has none."""

from __future__ import annotations

import numpy as np

from engine import quat
from input.controller_view import controller_camera
from input.hub import InputHub
from input.phone_frames import arkit_to_stick
from input.sample import PoseSample
from input.source import PoseSource
from tests.input.conftest import build_app


class Feed(PoseSource):
    threaded = False


def _app_with(sample: PoseSample):  # type: ignore[no-untyped-def]
    src = Feed("feed")
    app = build_app(InputHub([src]))
    src.push(sample)
    app.step()
    return app


def test_no_controller_no_view():
    app = build_app(InputHub([Feed("feed")]))
    app.step()
    assert controller_camera(app.world) is None


def test_a_6dof_phone_camera_is_its_own_pose():
    q_phone = quat.from_axis_angle([0.0, 1.0, 0.0], 0.4)  # an ARKit/WebXR camera turned left
    sample = PoseSample(
        time=0.0, source="web:1", orientation=arkit_to_stick(q_phone), position=np.array([0.2, 0.1, 0.0])
    )
    app = _app_with(sample)
    cam = controller_camera(app.world)
    assert cam is not None
    from engine.components import Stick

    stick = app.world.query(Stick)[0][1]
    assert np.allclose(cam.eye, stick.pivot)
    assert np.allclose(cam.forward, stick.direction, atol=1e-9)
    assert np.allclose(cam.rotation[:, 1], quat.rotate(stick.orientation, [0.0, 1.0, 0.0]), atol=1e-9)
    # Uncalibrated, the stick is the phone's own pose: the view is the phone camera's.
    assert np.allclose(cam.rotation, quat.to_matrix(q_phone), atol=1e-9)


def test_the_mouse_has_no_view_of_its_own():
    sample = PoseSample(
        time=0.0, source="mouse", orientation=quat.identity(), position=np.array([0.0, 1.5, 4.0]), mode="world"
    )
    assert controller_camera(_app_with(sample).world) is None
