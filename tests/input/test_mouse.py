"""The mouse: a stick held at the camera; drag in the plane at the grab depth, wheel, flick."""

import numpy as np
import pygame

from engine.components import Stick
from input.hub import InputHub
from input.mouse import MouseSource


class PinholeCamera:
    """A camera at (0,1.5,-4) looking along +Z with a 90° vertical field of view."""

    eye = np.array([0.0, 1.5, -4.0])
    forward = np.array([0.0, 0.0, 1.0])

    def ray(self, px, py, width, height):
        x = (2 * px / width - 1) * width / height
        y = 1 - 2 * py / height
        d = np.array([-x, y, 1.0])  # screen right is -X when looking along +Z
        return self.eye.copy(), d / np.linalg.norm(d)


def ev(kind, **kw):
    return pygame.event.Event(kind, **kw)


def test_event_types_match_pygame():
    from input import mouse

    assert (mouse.MOUSEMOTION, mouse.MOUSEBUTTONDOWN, mouse.MOUSEBUTTONUP, mouse.MOUSEWHEEL) == (
        pygame.MOUSEMOTION,
        pygame.MOUSEBUTTONDOWN,
        pygame.MOUSEBUTTONUP,
        pygame.MOUSEWHEEL,
    )


def test_drag_in_the_plane_at_grab_depth_and_wheel(make_app):
    cam, size = PinholeCamera(), (800, 600)
    mouse = MouseSource(plane="view", wheel_step=0.25)
    app = make_app(InputHub([mouse]))
    # The puppet stand-in is at (0,0.95,0): find its pixel (below the centre).
    py = 300 + 300 * (0.55 / 4.0)
    assert mouse.handle_event(ev(pygame.MOUSEBUTTONDOWN, pos=(400, py), button=1), cam, size, now=0.0)
    app.step()
    stick = app.world.query(Stick)[0][1]
    held = stick.grabbed
    assert held is not None and np.isclose(stick.tip[2] - cam.eye[2], 4.0)
    mouse.handle_event(ev(pygame.MOUSEMOTION, pos=(200, py), rel=(-200, 0), buttons=(1, 0, 0)), cam, size, now=0.5)
    app.step()
    assert np.isclose(stick.tip[2], 0.0) and stick.tip[0] > 1.0  # same depth, moved to screen-left (+X)
    mouse.handle_event(ev(pygame.MOUSEWHEEL, x=0, y=-2), cam, size, now=0.6)
    app.step()
    assert np.isclose(stick.tip[2], 0.5)  # two notches pushed it 0.5 m further away
    assert not mouse.handle_event(ev(pygame.MOUSEBUTTONDOWN, pos=(1, 1), button=3), cam, size)  # orbit: camera's
    mouse.handle_event(ev(pygame.MOUSEBUTTONUP, pos=(200, py), button=1), cam, size, now=0.7)
    app.step()
    assert stick.grabbed is None and stick.released == held


def test_ground_plane_drag_keeps_height_and_wheel_lifts(make_app):
    cam, size = PinholeCamera(), (800, 600)
    mouse = MouseSource(plane="ground", wheel_step=0.1)
    app = make_app(InputHub([mouse]))
    py = 300 + 300 * (0.55 / 4.0)
    mouse.handle_event(ev(pygame.MOUSEBUTTONDOWN, pos=(400, py), button=1), cam, size, now=0.0)
    app.step()
    stick = app.world.query(Stick)[0][1]
    assert stick.grabbed is not None
    height = stick.tip[1]
    mouse.handle_event(
        ev(pygame.MOUSEMOTION, pos=(300, py + 60), rel=(-100, 60), buttons=(1, 0, 0)), cam, size, now=0.5
    )
    app.step()
    assert np.isclose(stick.tip[1], height)  # dragging stays on the horizontal plane
    assert stick.tip[2] < -0.5 or stick.tip[0] > 0.5  # and moved over the ground
    mouse.handle_event(ev(pygame.MOUSEWHEEL, x=0, y=2), cam, size, now=0.6)
    app.step()
    assert np.isclose(stick.tip[1], height + 0.2)  # wheel up lifts by two notches


def test_quick_upward_drag_is_one_flick():
    cam, size = PinholeCamera(), (800, 600)
    mouse = MouseSource()
    mouse.handle_event(ev(pygame.MOUSEBUTTONDOWN, pos=(400, 500), button=1), cam, size, now=0.0)
    for i, y in enumerate((400, 300, 200)):
        mouse.handle_event(
            ev(pygame.MOUSEMOTION, pos=(400, y), rel=(0, -100), buttons=(1, 0, 0)), cam, size, now=0.03 * (i + 1)
        )
    mouse.handle_event(ev(pygame.MOUSEMOTION, pos=(400, 199), rel=(0, -1), buttons=(1, 0, 0)), cam, size, now=1.0)
    flicks = [s.flick for s in mouse.drain()]
    assert flicks == [False, True, False, False, False]


def test_a_flick_after_a_pause_is_judged_from_where_the_cursor_rested():
    """The press, a rest longer than the flick window, then a quick rise: the first move already
    flicks, and the stick keeps pointing where the cursor rested (before, the first move lifted the
    puppet and the flick came one move late, to a puppet already off its feet)."""
    cam, size = PinholeCamera(), (640, 360)
    mouse = MouseSource()
    mouse.handle_event(ev(pygame.MOUSEBUTTONDOWN, pos=(320, 200), button=1), cam, size, now=0.0)
    first = mouse.handle_event(
        ev(pygame.MOUSEMOTION, pos=(320, 170), rel=(0, -30), buttons=(1, 0, 0)), cam, size, now=0.6
    )
    assert first
    press, move = mouse.drain()
    assert move.flick  # 30 px of 360 within the window: a flick at once
    assert np.allclose(move.orientation, press.orientation) and np.allclose(move.position, press.position)
    # A slow drag is still a drag: 2 px a step, 0.05 s apart, never 0.08 of the height within 0.15 s.
    mouse.handle_event(ev(pygame.MOUSEBUTTONUP, pos=(320, 170), button=1), cam, size, now=0.7)
    mouse.handle_event(ev(pygame.MOUSEBUTTONDOWN, pos=(320, 200), button=1), cam, size, now=2.0)
    for k in range(1, 30):
        mouse.handle_event(
            ev(pygame.MOUSEMOTION, pos=(320, 200 - 2 * k), rel=(0, -2), buttons=(1, 0, 0)),
            cam,
            size,
            now=2.0 + 0.05 * k,
        )
    assert not any(s.flick for s in mouse.drain())
