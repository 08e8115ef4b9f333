"""Every kind of artifact the product saves reopens with what was saved, value for value.

One test per format, through the same save and load functions the product uses (all of
them atomic and verified by :mod:`engine.atomic`); numbers compare bit for bit except
where a loader documents a renormalisation (clip rotations: to 1e-15).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.clips import default_clips

UNIT = st.floats(0.0, 1.0, allow_nan=False)


@settings(max_examples=25, deadline=None)
@given(ground=UNIT, boxes=st.lists(st.tuples(UNIT, UNIT, UNIT, UNIT), max_size=5), stage=st.sampled_from(range(4)))
def test_tasbada_progress(tmp_path_factory, ground: float, boxes, stage: int) -> None:  # type: ignore[no-untyped-def]
    from games.tasbada.quest import STAGES, Mark
    from games.tasbada.save import Progress, load_progress, save_progress

    marks = [Mark("box", [[a, b], [c, d]]) for a, b, c, d in boxes]
    progress = Progress(list(STAGES[: stage + 1]), marks, round(ground, 6), STAGES[stage], "room.jpg")
    back = load_progress(save_progress(tmp_path_factory.mktemp("t") / "save.json", progress))
    assert back is not None and (back.reached, back.stage, back.ground_v, back.photo) == (
        progress.reached,
        progress.stage,
        progress.ground_v,
        progress.photo,
    )
    assert [m.to_json() for m in back.marks] == [m.to_json() for m in marks]


def test_snowman_field(tmp_path: Path) -> None:
    from engine.atomic import atomic_write_bytes
    from games.snowman.field_save import FIELD_HEADS, load_field, snapshot
    from input.hub import InputHub
    from puppetphone.games import make_app

    app = make_app("snowman", 3, InputHub())
    app.run_steps(5)
    snap = snapshot(app.world)
    path = atomic_write_bytes(tmp_path / "field.json", json.dumps(snap).encode(), expect_head=FIELD_HEADS)
    assert load_field(path) == json.loads(json.dumps(snap))


def test_clip_and_its_root_curve(tmp_path: Path) -> None:
    from engine.clipfile import load_clip_curve, save_clip

    walk = default_clips()["walk"]
    back, _ = load_clip_curve(save_clip(walk, tmp_path / "walk.ppclip"))
    assert back.root.tobytes() == walk.root.tobytes() and back.fps == walk.fps and back.markers == walk.markers
    assert np.allclose(back.rotations, walk.rotations, rtol=0, atol=1e-15)


def test_mocurves_session(tmp_path: Path) -> None:
    from authoring.mocurves import EditSession, load_session, save_session

    s = EditSession(default_clips()["crouch_walk"], tau=5, sigma=0.2)
    s.scale_arrow("l_foot", 10, 0.2)
    back = load_session(save_session(s, tmp_path / "c.ppclip"))
    assert back.scales.tobytes() == s.scales.tobytes() and (back.tau, back.sigma) == (5, 0.2)


def test_keyframe_curves(tmp_path: Path) -> None:
    from authoring.keyframe_curves.session import CurveSession, load_curves, save_curves

    clip = CurveSession.from_spec("walk").clip
    back = load_curves(save_curves(clip, tmp_path / "k.ppclip"))
    for name in ("times", "values", "out_x", "out_y", "in_x", "in_y"):
        assert np.asarray(getattr(back.curves, name)).tobytes() == np.asarray(getattr(clip.curves, name)).tobytes()


def test_clip_library(tmp_path: Path) -> None:
    from engine.cliplib.library import ClipLibrary, clip_digest
    from engine.cliplib.roles import conform
    from engine.humanoid import humanoid_skeleton

    lib = ClipLibrary(tmp_path / "lib")
    entry = lib.add(
        conform(default_clips()["walk"].resampled(50.0), "walk"), "walk", humanoid_skeleton(), default_clips()
    )
    assert clip_digest(ClipLibrary(tmp_path / "lib").load()["walk"]) == entry.sha256


def test_recording(tmp_path: Path) -> None:
    from input.hub import InputHub
    from input.recording import Recorder, RecordingHeader, read_recording
    from puppetphone.games import make_app

    hub = InputHub()
    app = make_app("sandbox", 4, hub)
    from engine.hashing import state_hash

    hashes: list[str] = []
    with Recorder(tmp_path / "s.rec", RecordingHeader("sandbox", 4, app.world.dt, setup={"puppets": 1})) as rec:
        rec.attach(app)
        app.on_step_end.append(lambda world: hashes.append(state_hash(world)))
        app.run_steps(20)
    back = read_recording(tmp_path / "s.rec")
    assert back.complete and back.hashes == hashes and back.header.setup == {"puppets": 1} and back.header.seed == 4
    assert back.header == rec.header and back.header.libraries["mujoco"] != "none"  # every field, the versions too
    again = tmp_path / "again.rec"
    with Recorder(again, back.header) as copy:  # written again from what was read: the same bytes
        for frame, digest, parts in zip(back.frames, back.hashes, back.parts, strict=True):
            copy.write(frame, digest, parts)
    assert again.read_bytes() == (tmp_path / "s.rec").read_bytes()
