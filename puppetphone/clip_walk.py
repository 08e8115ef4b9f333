"""How a puppet walks in the game: a scripted stick's walk, and its speed and foot-sliding figures.

The check behind ``play --clips`` (tests and ``bench clips``): a scripted phone walks the
sandbox puppet in a straight line at a steady pace through the real input path and the
session is recorded (:func:`record_stick_walk`); ``puppetphone play sandbox --source
replay:STICK --clips DIR --record OUT`` plays the same stick with other clips; then
:func:`walk_figures` replays OUT and measures, over the steady part of the walk:

- the speed error: the puppet's ground speed (its root motion, integrated by the
  game) against the speed the stick asks (its tip's ground speed), in %;
- foot sliding: the mean horizontal speed of each foot's lowest sole point (heel or toe
  tip, as :mod:`engine.clips.contacts` defines them) while the animation plants it:
  labelled planted by the clips holding most of the blend's weight
  (:func:`engine.blend.measure.blended_contacts`, each clip's own contacts). A height
  threshold is not used: a mocap swing toe skims the floor by a centimetre and is not a
  planted foot, while a built-in swing foot never comes that low, so a threshold
  would measure the two sets differently. In m/s: what an onlooker sees as skating,
  the runtime's IK and everything after the blend included.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from engine import quat
from engine.blend.locomotion import LocomotionPlayer
from engine.clips.contacts import FOOT_JOINTS, HEEL_OFFSET
from engine.components import Puppet, Transform, WorldPose
from engine.skeleton import Skeleton
from engine.statemachine import Brain
from input.source import PoseSource

__all__ = ["WalkFigures", "record_stick_walk", "walk_figures"]


@dataclass(frozen=True)
class WalkFigures:
    """Figures of the steady part of a walk (see the module docstring)."""

    requested: float
    """The stick tip's ground speed (m/s)."""
    played: float
    """The puppet's ground speed (m/s)."""
    speed_error_pct: float
    foot_slide: float
    frames: int


class _ScriptedPhone(PoseSource):
    """A 6-DoF phone fed from this thread, one ``"device"`` sample per step (no device thread)."""

    threaded = False

    def __init__(self) -> None:
        super().__init__("phone")
        self._status.connected = True


def record_stick_walk(
    path: str | Path,
    speed: float = 1.1,
    distance: float = 5.0,
    seed: int = 0,
    direction: tuple[float, float] = (0.6, -0.8),
    clips: dict | None = None,
) -> Path:
    """Record the sandbox puppet walked ``distance`` m along ground ``direction`` (x, z) at ``speed`` m/s by
    a phone, then let go. The default direction crosses the sandbox camera's view, so a screenshot shows
    the puppet side-on. ``clips`` (an :func:`engine.cliplib.embed.encode` value) plays authored clips.

    A phone rather than the mouse: its positions are floats, so the stick's speed is
    steady (a mouse moves in whole pixels, and a step without a new pixel reads as a
    stop, which makes the brain's request jump between a stroll and a run).
    """
    from engine.components import Grabbable
    from input.hub import InputHub
    from input.motionstick import StickConfig
    from input.recording import Recorder, RecordingHeader
    from input.sample import PoseSample
    from puppetphone.games import make_app

    phone = _ScriptedPhone()
    setup = {"scene": "empty", "puppets": 1, **({"clips": clips} if clips is not None else {})}
    app = make_app("sandbox", seed, InputHub([phone]), setup)
    world = app.world
    header = RecordingHeader(
        game="sandbox", seed=seed, dt=world.dt, sources=["phone"], setup=setup, extra={"session": "stick_walk"}
    )
    puppet = next(e for e, _ in world.query(Brain))
    pivot = np.array(world.resource(StickConfig).virtual_pivot, dtype=np.float64)
    state = {"position": np.zeros(3), "orientation": quat.identity()}

    def push(n: int = 1, touch: bool | None = None, calibrate: bool = False) -> None:
        for _ in range(n):
            phone.push(
                PoseSample(
                    time=world.frame * world.dt,
                    source="phone",
                    orientation=state["orientation"],
                    position=state["position"].copy(),
                    touch=touch,
                    calibrate=calibrate,
                )
            )
            app.step()

    with Recorder(path, header).attach(app):
        push(10)
        push(calibrate=True)
        anchor = world.get(puppet, Grabbable).anchor(world.get(puppet, Transform))
        d = anchor - pivot
        state["orientation"] = quat.between(np.array([0.0, 0.0, 1.0]), d / np.linalg.norm(d))
        push()
        push(touch=True)
        push(15)
        steps = max(1, int(round(distance / speed / world.dt)))
        way = np.array([direction[0], 0.0, direction[1]]) / float(np.hypot(*direction))
        for k in range(1, steps + 1):
            state["position"] = way * (distance * k / steps)
            push()
        push(30)
        push(touch=False)
        push(20)
    return Path(path)


def _soles(sk: Skeleton, wp: WorldPose) -> np.ndarray:
    """``[2, 2, 3]`` heel and toe-tip world points of both feet."""
    out = np.empty((2, 2, 3))
    for s, name in enumerate(FOOT_JOINTS):
        j = sk.index(name)
        out[s, 0] = wp.positions[j] + quat.rotate(wp.rotations[j], HEEL_OFFSET)
        out[s, 1] = wp.positions[j] + quat.rotate(wp.rotations[j], sk.tips[j])
    return out


def walk_figures(recording: str | Path, settle: float = 1.0) -> WalkFigures:
    """Replay ``recording`` (a sandbox session) and measure its steady walk.

    The steady part: steps where the brain asks for a speed within 10 % of the median
    request while walking, from ``settle`` seconds after the first such step (the blend
    eases in) to the last.
    """
    from input.recording import read_recording
    from input.replay import replay_hub
    from puppetphone.games import load_game, make_app

    rec = read_recording(recording)
    h = rec.header
    app = make_app(h.game, h.seed, replay_hub(rec), load_game(h.game).replay_setup(h.setup))
    world = app.world
    entity = next(e for e, _ in world.query(Brain))
    sk = world.get(entity, Puppet).skeleton
    from engine.blend.locomotion import BlendLibrary
    from engine.blend.measure import blended_contacts
    from engine.clips import foot_contacts

    space = world.resource(BlendLibrary)[world.get(entity, LocomotionPlayer).library_key].space
    tracks = [foot_contacts(c) for c in space.clips]
    from engine.components import Stick

    positions, requests, soles, points, phases, tips = [], [], [], [], [], []
    last = max((f.frame for f in rec.frames), default=-1)
    while world.frame <= last:
        app.step()
        player = world.get(entity, LocomotionPlayer)
        positions.append(np.array(world.get(entity, Transform).position))
        requests.append(player.speed if player.override is None else np.nan)
        points.append(np.array(player.point))
        tips.append(next(np.array(st.tip) for _, st in world.query(Stick)))
        phases.append(player.phase)
        wp = world.try_get(entity, WorldPose)
        soles.append(_soles(sk, wp) if wp is not None else np.full((2, 2, 3), np.nan))
    req = np.array(requests)
    moving = np.nan_to_num(req) > 0.2
    if not moving.any():
        raise ValueError(f"{recording}: the puppet never walked")
    median = float(np.median(req[moving]))
    steady = np.flatnonzero(moving & (np.abs(req - median) <= 0.1 * median))
    first = steady[0] + int(round(settle / world.dt))
    window = steady[steady >= first]
    window = window[: len(window) - 1]
    if len(window) < 30:
        raise ValueError(f"{recording}: only {len(window)} steady steps to measure")
    a, b = int(window[0]), int(window[-1])
    pos = np.array(positions)
    played = float(np.linalg.norm(pos[b, [0, 2]] - pos[a, [0, 2]]) / ((b - a) * world.dt))
    tip = np.array(tips)
    requested = float(np.linalg.norm(tip[b, [0, 2]] - tip[a, [0, 2]]) / ((b - a) * world.dt))
    pts = np.array(soles)[a : b + 2]  # [T, side, heel/toe, 3]
    low = np.argmin(pts[..., 1], axis=-1)
    here = np.take_along_axis(pts[:-1], low[:-1, :, None, None], axis=2)[:, :, 0]
    there = np.take_along_axis(pts[1:], low[:-1, :, None, None], axis=2)[:, :, 0]
    labels = blended_contacts(space, space.weights(np.array(points[a : b + 2])), np.array(phases[a : b + 2]), tracks)
    contact = labels[:-1] & labels[1:]
    speed = np.linalg.norm((there - here)[..., [0, 2]], axis=-1) / world.dt
    slide = float(speed[contact].mean()) if contact.any() else 0.0
    return WalkFigures(requested, played, 100.0 * abs(played - requested) / requested, slide, b - a)
