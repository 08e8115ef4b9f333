"""The scene stream's format: quantised rows, delta frames, the GLB a phone starts from, and the page's reader.

The page's own decoder (``page/stream.js``) runs under node on frames the engine
encoded, so a change on one side that the other does not follow fails here.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import input.web
from engine.render.scene import GroundMarks, RenderScene
from input.web.scene_glb import read_scene_glb, scene_glb
from input.web.scene_stream import KINDS, CameraPose, FrameError, SceneState, decode_frame, encode_frame, quantise

CAM = CameraPose((0.0, 1.5, 4.0), (1.0, 0.0, 0.0, 0.0), 60.0)
PAGE = Path(input.web.__file__).parent / "page"
needs_node = pytest.mark.skipif(shutil.which("node") is None, reason="no node executable: apt-get install nodejs")


def tracked(scene: RenderScene, rolled: list[tuple[int, int, int, int]]) -> RenderScene:
    """``scene`` with a 240 × 240 snow track grid (10 cm cells) cleared over each ``(row0, col0, rows, cols)``,
    and two footprints."""
    amount = np.zeros((240, 240), dtype=np.float32)
    for r0, c0, h, w in rolled:
        amount[r0 : r0 + h, c0 : c0 + w] = np.linspace(0.2, 1.0, w)
    scene.marks = GroundMarks(amount, -12.0, -12.0, 0.1)
    scene.add_prints(np.array([[0.5, 1.0], [0.8, 1.3]]), np.array([0.0, 1.2]), strength=np.array([1.0, 0.4]))
    return scene


def scene_with(n_capsules: int, shift: float = 0.0, moved: int | None = None) -> RenderScene:
    rng = np.random.default_rng(3)
    a = rng.uniform(-3, 3, (n_capsules, 3))
    b = a + rng.uniform(-0.3, 0.3, (n_capsules, 3))
    if moved is not None:
        a[:moved] += shift
        b[:moved] += shift
    s = RenderScene()
    s.add_capsules(a, b, 0.05, color=(0.85, 0.45, 0.3))
    s.add_sphere([1.0, 0.3, -2.0], 0.3)
    s.add_box([2.0, 0.5, 0.0], [0.2, 0.5, 0.3], rotation=(0.92388, 0.0, 0.38268, 0.0))
    s.add_line([0.0, 1.0, 0.0], [0.5, 0.2, 0.0], color=(1.0, 0.55, 0.15))
    s.add_points(np.array([[0.5, 0.2, 0.0]]), size=0.05)
    s.add_cones(np.array([[-5.0, 0.9, -4.5], [-5.0, 1.8, -4.5]]), np.array([[-5.0, 2.6, -4.5], [-5.0, 3.3, -4.5]]), 0.9)
    return s


def same(x: SceneState, y: SceneState) -> bool:
    rows = all(np.array_equal(x.rows[k], y.rows[k]) for k in KINDS)
    if x.marks is None or y.marks is None:
        return rows and x.marks is y.marks
    return rows and np.array_equal(x.marks.cells, y.marks.cells) and x.marks.same_grid(y.marks)


def test_the_tracks_go_once_whole_then_as_the_cells_a_ball_cleared():
    """A rolled strip costs its rectangle; two strips far apart cost a list of cells, not the rectangle
    between them; an unchanged grid costs one byte. (Sending the whole grid each time fails the sizes;
    a decoder that drops the base grid fails ``same``.)"""
    base = quantise(tracked(scene_with(3), [(100, 100, 4, 6)]), 1, 0.0, CAM)
    plain = encode_frame(base, quantise(scene_with(3), 2, 0.0, CAM))  # the tracks gone: one byte
    still = encode_frame(base, quantise(tracked(scene_with(3), [(100, 100, 4, 6)]), 2, 0.0, CAM))
    assert len(still) == len(plain)
    rolled = quantise(tracked(scene_with(3), [(100, 100, 4, 6), (104, 103, 3, 5)]), 3, 0.0, CAM)
    frame = encode_frame(base, rolled)
    assert same(decode_frame(base, frame), rolled)
    assert 3 * 5 <= len(frame) - len(still) <= 3 * 5 + 8 + 14 + 2
    apart = quantise(tracked(scene_with(3), [(100, 100, 4, 6), (5, 5, 2, 2), (230, 230, 2, 2)]), 4, 0.0, CAM)
    frame = encode_frame(base, apart)
    assert same(decode_frame(base, frame), apart)
    assert len(frame) - len(still) <= 8 * 5 + 4 + 16, "two small strips far apart sent as the rectangle between them"
    whole = encode_frame(SceneState.empty(), apart)
    assert same(decode_frame(SceneState.empty(), whole), apart) and len(whole) > 240 * 240 / 5
    glb_state = read_scene_glb(scene_glb(apart, scene_with(3)))[1]
    assert same(glb_state, apart)
    assert same(decode_frame(glb_state, encode_frame(glb_state, rolled)), rolled)


def test_a_frame_takes_the_phone_exactly_to_the_new_state_and_sends_only_what_moved():
    base = quantise(scene_with(40), 1, 0.0, CAM)
    walked = quantise(scene_with(40, shift=0.02, moved=20), 2, 0.0, CAM)  # 2 cm: int8 differences
    frame = encode_frame(base, walked)
    assert same(decode_frame(base, frame), walked)
    still = encode_frame(base, quantise(scene_with(40), 3, 0.0, CAM))
    # 20 moved capsules: their 6 end-point columns (not radius, colour, outline) at one byte each, plus masks.
    assert len(still) < 75, "an unchanged scene costs more than its header and row counts"
    assert 20 * 6 <= len(frame) - len(still) < 20 * 6 + 16
    full = encode_frame(SceneState.empty(), walked)
    assert same(decode_frame(SceneState.empty(), full), walked)
    assert len(full) > 2 * len(frame)


def test_a_jump_too_big_for_a_byte_is_sent_as_whole_values_and_rows_can_come_and_go():
    base = quantise(scene_with(10), 1, 0.0, CAM)
    jumped = quantise(scene_with(10, shift=1.5, moved=3), 2, 0.0, CAM)
    assert same(decode_frame(base, encode_frame(base, jumped)), jumped)
    fewer = quantise(scene_with(4), 3, 0.0, CAM)
    more = quantise(scene_with(25), 4, 0.0, CAM)
    assert same(decode_frame(jumped, encode_frame(jumped, fewer)), fewer)
    assert same(decode_frame(fewer, encode_frame(fewer, more)), more)


def test_quantisation_keeps_millimetres_and_clamps_what_is_far_away():
    s = RenderScene()
    s.add_capsule([0.0004, 1.2344, -7.0], [0.0, 40.0, 0.0], 0.05)
    rows = quantise(s, 0, 0.0, CAM).rows["capsules"][0]
    assert rows[:3].tolist() == [0, 1234, -7000]
    assert rows[4] == 32767  # 40 m is past the int16 range of millimetres: clamped, never wrapped


def test_the_trees_go_once_and_then_cost_three_bytes_a_frame():
    """Conifer tiers are rows of their own kind: in the GLB, then unchanged (a row count and a mode byte).
    (A codec that left the cones out fails ``same``; one that resent them fails the size.)"""
    base = quantise(scene_with(3), 1, 0.0, CAM)
    assert base.rows["cones"].shape == (2, 11) and base.rows["cones"][1, 4] == 3300
    glb_state = read_scene_glb(scene_glb(base, scene_with(3)))[1]
    assert same(glb_state, base)
    moved = quantise(scene_with(3, 0.02, 3), 2, 0.0, CAM)
    frame = encode_frame(base, moved)
    assert same(decode_frame(glb_state, frame), moved)

    def treeless(st: SceneState) -> SceneState:
        return SceneState(st.step, 0.0, CAM, {**st.rows, "cones": st.rows["cones"][:0]})

    assert len(frame) == len(encode_frame(treeless(base), treeless(moved))), "unchanged cones cost more than 3 bytes"


def test_the_falling_snow_goes_once_in_the_glb_as_the_flakes_and_the_rule_that_moves_them():
    """The snowman's snowfall rides in the GLB (a VEC4 accessor of start and phase per flake, and the
    rule's constants), and the page's rule (render.js FLAKE_VS) applied to what the GLB carries puts each
    flake where the desktop draws it at that step. (A GLB without the flakes, or with the wrong speed or
    sway, fails.)"""
    from games.snowman.scenery import SNOWFALL

    state = quantise(scene_with(3), 600, 0.0, CAM)
    glb = scene_glb(state, scene_with(3), SNOWFALL, 1 / 60)
    extras, _ = read_scene_glb(glb)
    f = extras["snowfall"]
    doc = json.loads(glb[20 : 20 + int.from_bytes(glb[12:16], "little")])
    view = doc["bufferViews"][doc["accessors"][f["accessor"]]["bufferView"]]
    blob = glb[20 + int.from_bytes(glb[12:16], "little") + 8 :]
    flakes = np.frombuffer(blob, "<f4", 4 * f["count"], view["byteOffset"]).reshape(-1, 4).astype(np.float64)
    assert f["count"] == 900 and f["step_seconds"] == pytest.approx(1 / 60)
    time = 600 * f["step_seconds"]
    # The page's rule, with the clock's terms reduced as render.js does (fall mod height, phases mod 2π).
    fall, turn = (f["speed"] * time) % f["height"], 2 * np.pi
    a, b = (f["sway_rates"][0] * time) % turn, (f["sway_rates"][1] * time) % turn
    page = np.column_stack(
        [
            flakes[:, 0] + f["sway"] * np.sin(a + flakes[:, 3]),
            (flakes[:, 1] - fall) % f["height"],
            flakes[:, 2] + f["sway"] * np.cos(b + flakes[:, 3]),
        ]
    )
    desktop = RenderScene()
    SNOWFALL.draw(desktop, time)
    assert np.abs(page - desktop.points.data[:, :3]).max() < 1e-3
    assert read_scene_glb(scene_glb(state, scene_with(3)))[0]["snowfall"] is None


@pytest.mark.fuzz
def test_fuzz_byte_mutations_of_a_scene_frame(campaign, mutations, fuzz_budget):
    """Mutated frames (all kinds, cones and tracks included) decode to rows of the right shape or raise one
    FrameError; nothing else escapes the boundary. (A reader that reshapes a frame of changed rows with no
    changed column raised numpy's ValueError here.)"""
    from input.web.scene_stream import SCALES

    cases, seed = fuzz_budget(2000)
    c = campaign(FrameError)
    base = quantise(tracked(scene_with(6), [(100, 100, 4, 6)]), 1, 0.0, CAM)
    moved = quantise(tracked(scene_with(6, 0.05, 4), [(100, 100, 4, 6), (5, 5, 2, 2), (230, 230, 2, 2)]), 2, 0.0, CAM)
    for good in (encode_frame(base, moved), encode_frame(SceneState.empty(), base)):
        for data in mutations(good, cases // 2, seed):
            state = c.run(decode_frame, base, data)
            if state is not None:
                for kind, scales in SCALES.items():
                    assert state.rows[kind].ndim == 2 and state.rows[kind].shape[1] == len(scales)
    c.check("scene frames")


@pytest.mark.parametrize("cut", ["short", "magic", "trailing"])
def test_bytes_that_are_not_a_frame_are_refused_with_a_reason(cut):
    base = quantise(scene_with(5), 1, 0.0, CAM)
    frame = encode_frame(SceneState.empty(), quantise(scene_with(5, 0.01, 2), 2, 0.0, CAM))
    bad = {"short": frame[:-3], "magic": b"XX" + frame[2:], "trailing": frame + b"\0"}[cut]
    with pytest.raises(FrameError):
        decode_frame(SceneState.empty() if cut != "magic" else base, bad)


def test_the_glb_is_a_gltf_with_a_ground_mesh_and_the_rows_the_first_frame_builds_on():
    scene = scene_with(12)
    state = quantise(scene, 7, 0.0, CAM)
    glb = scene_glb(state, scene)
    assert glb[:4] == b"glTF" and len(glb) % 4 == 0
    extras, back = read_scene_glb(glb)
    assert same(back, state) and back.step == 7
    assert extras["ground"]["color"] == list(scene.ground.color)
    doc = json.loads(glb[20 : 20 + int.from_bytes(glb[12:16], "little")])
    assert doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] == 0
    nxt = quantise(scene_with(12, 0.01, 5), 8, 0.0, CAM)
    assert same(decode_frame(back, encode_frame(back, nxt)), nxt)


@needs_node
def test_the_pages_reader_decodes_the_engines_frames_to_the_same_rows(tmp_path):
    scene = tracked(scene_with(15), [(10, 10, 3, 3)])
    first = quantise(scene, 1, 0.0, CAM)
    states = [
        quantise(tracked(scene_with(15, 0.02 * i, 8), [(10, 10, 3, 3 + i)]), 1 + i, 0.0, CAM) for i in range(1, 4)
    ]
    states.append(
        quantise(tracked(scene_with(3, 2.0, 3), [(10, 10, 3, 6), (200, 3, 1, 1)]), 9, 0.0, CAM)
    )  # int16, fewer rows
    blobs = [scene_glb(first, scene)]
    prev = first
    for s in states:
        blobs.append(encode_frame(prev, s))
        prev = s
    for i, blob in enumerate(blobs):
        (tmp_path / f"{i}.bin").write_bytes(blob)
    script = f"""
const fs = require("fs"); const {{ readSceneGlb, decodeFrame, KINDS }} = require({json.dumps(str(PAGE / "stream.js"))});
const buf = (i) => {{ const b = fs.readFileSync({json.dumps(str(tmp_path))} + "/" + i + ".bin"); return b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength); }};
const glb = readSceneGlb(buf(0)); let state = glb.state;
for (let i = 1; i < {len(blobs)}; i++) state = decodeFrame(state, glb.scales, buf(i));
const out = {{}}; for (const k of KINDS) out[k] = Array.from(state.rows[k]);
const m = state.marks, on = [];
m.cells.forEach((v, i) => {{ if (v) on.push([i, v]); }});
console.log(JSON.stringify({{ step: state.step, rows: out, marks: [m.nx, m.nz, m.x0, m.z0, m.cell, on] }}));
"""
    res = subprocess.run(["node", "-e", script], capture_output=True, text=True, timeout=30)
    assert res.returncode == 0, res.stderr
    page = json.loads(res.stdout)
    assert page["step"] == 9
    for kind in KINDS:
        assert page["rows"][kind] == states[-1].rows[kind].reshape(-1).tolist(), kind
    want = states[-1].marks
    flat = want.cells.reshape(-1)
    assert page["marks"][:5] == [240, 240, want.x0, want.z0, want.cell]
    assert page["marks"][5] == [[int(i), int(flat[i])] for i in np.flatnonzero(flat)]


def blend_script(tmp_path: Path, second_step: int, probe: str, behind: bool = False) -> object:
    """Node: a page's SceneStream given the GLB at 1000 ms and a frame of step ``second_step`` (both capsules
    10 cm along every axis) at 1020 ms, marked ``behind`` (it replaced a frame held for a busy drawer); the
    JSON of ``probe`` (``s``: the stream; ``x(t)``: the first capsule's x drawn at ``t``)."""
    scene = scene_with(2)
    first = quantise(scene, 1, 0.0, CAM)
    moved = quantise(scene_with(2, 0.1, 2), second_step, 0.0, CAM)
    (tmp_path / "0.bin").write_bytes(scene_glb(first, scene))
    (tmp_path / "1.bin").write_bytes(encode_frame(first, moved))
    script = f"""
const fs = require("fs"); const {{ SceneStream, StreamDecoder }} = require({json.dumps(str(PAGE / "stream.js"))});
globalThis.performance = {{ timeOrigin: 0 }};
const buf = (i) => {{ const b = fs.readFileSync({json.dumps(str(tmp_path))} + "/" + i + ".bin"); return b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength); }};
const s = new SceneStream(), d = new StreamDecoder(); s.receive(d, buf(0), 1000); s.sample(1010);
const f = d.receive(buf(1)); f.arrived = f.decoded = 1020; f.behind = {json.dumps(behind)}; s.accept(f, 1020);
const x = (t) => s.sample(t).rows.capsules[0];
console.log(JSON.stringify({probe}));
"""
    res = subprocess.run(["node", "-e", script], capture_output=True, text=True, timeout=30)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout)


@needs_node
def test_the_page_blends_frames_steps_apart_and_holds_the_last_one_when_the_next_is_late(tmp_path):
    """Frames three steps apart (back-pressure gave a slow phone every third): the picture moves from the
    last frame to the new one over the arrival interval, then holds. (Blending every frame, whatever the
    step gap, fails the next test; never blending fails this one.)"""
    at_arrival, wants, halfway, done, late = blend_script(
        tmp_path, 4, "[x(1020), s.wants(1025), x(1030), x(1040), x(5000)]"
    )
    scene, moved = quantise(scene_with(2), 1, 0.0, CAM), quantise(scene_with(2, 0.1, 2), 4, 0.0, CAM)
    a0, a1 = scene.rows["capsules"][0, 0] / 1000, moved.rows["capsules"][0, 0] / 1000
    assert at_arrival == pytest.approx(a0, abs=1e-6), "a new frame should start from where the last one was drawn"
    assert wants, "a blend under way should ask for its next picture"
    assert halfway == pytest.approx((a0 + a1) / 2, abs=1e-6)
    assert done == pytest.approx(a1, abs=1e-6) and late == pytest.approx(a1, abs=1e-6), (
        "a late frame must hold, not run on"
    )


@needs_node
def test_the_page_shows_a_frame_one_step_after_the_last_at_once_and_never_draws_the_same_picture_twice(tmp_path):
    """At the engine's pace (frames a step apart) there is nothing between two frames: the first drawing
    after a frame shows it (blending there showed the frame before, a step late); once drawn, the stream
    wants no drawing until the next frame. (Blending whatever the gap fails the first assertion; a
    ``wants`` that stays true fails the second.)"""
    at_arrival, time, wants_after, late = blend_script(
        tmp_path, 2, "[x(1020), s.sample(1021).time, s.wants(1022), x(5000)]"
    )
    a1 = quantise(scene_with(2, 0.1, 2), 2, 0.0, CAM).rows["capsules"][0, 0] / 1000
    assert at_arrival == pytest.approx(a1, abs=1e-6) and time == 2, (
        "a frame a step after the last one is shown as it is"
    )
    assert not wants_after, "the same picture should not be drawn again"
    assert late == pytest.approx(a1, abs=1e-6)


@needs_node
def test_the_page_does_not_blend_towards_a_frame_its_drawer_was_too_busy_to_take_in_time(tmp_path):
    """Frames three steps apart because the drawer was busy (the stream worker replaced the one it held):
    the newest is shown as it is; blending would spend the busy drawer's next drawing on an older picture.
    (Ignoring ``behind`` fails it.)"""
    at_arrival, wants_after = blend_script(tmp_path, 4, "[x(1020), s.wants(1021)]", behind=True)
    assert at_arrival == pytest.approx(
        quantise(scene_with(2, 0.1, 2), 4, 0.0, CAM).rows["capsules"][0, 0] / 1000, abs=1e-6
    )
    assert not wants_after


@needs_node
def test_the_page_softens_the_tracks_as_the_desktop_does_before_drawing_them(tmp_path):
    """The page blurs the grid once per change (so its shader reads one texel a pixel); the result is the
    desktop's ``soften_marks`` to within rounding. (A page that skipped the blur differs by up to 128.)"""
    from engine.render.environment import soften_marks

    cells = np.random.default_rng(5).integers(0, 256, (7, 11)).astype(np.uint8)
    cells[2:4] = 0
    script = f"""
const {{ softenMarks }} = require({json.dumps(str(PAGE / "stream.js"))});
const m = softenMarks({{ nx: 11, nz: 7, cells: Uint8Array.from({json.dumps(cells.reshape(-1).tolist())}) }});
console.log(JSON.stringify(Array.from(m.cells)));
"""
    res = subprocess.run(["node", "-e", script], capture_output=True, text=True, timeout=30)
    assert res.returncode == 0, res.stderr
    page = np.array(json.loads(res.stdout)).reshape(7, 11)
    desktop = soften_marks(cells.astype(np.float32) / 255.0).astype(int)
    assert np.abs(page - desktop).max() <= 1


def worker_frames(tmp_path: Path) -> tuple[RenderScene, list[bytes]]:
    """A GLB and six frames of a scene whose tracks change at steps 6 and 7, written to ``tmp_path/<i>.bin``."""
    scene = tracked(scene_with(4), [(10, 10, 3, 3)])
    states = [quantise(scene, 1, 0.0, CAM)]
    for i in range(2, 8):
        strips = [(10, 10, 3, 3)] + ([(50, 50, 2, 2)] if i >= 6 else []) + ([(60, 70, 1, 4)] if i >= 7 else [])
        states.append(quantise(tracked(scene_with(4, 0.01 * i, 2), strips), i, 0.0, CAM))
    blobs = [scene_glb(states[0], scene)] + [encode_frame(a, b) for a, b in zip(states, states[1:], strict=False)]
    for i, blob in enumerate(blobs):
        (tmp_path / f"{i}.bin").write_bytes(blob)
    return scene, blobs


def run_worker(tmp_path: Path, body: str) -> dict:
    """``stream_worker.js`` under node with a fake WebSocket and a drawer port that logs what it gets (and
    feeds it to a SceneStream, as the render worker does); ``body`` prints the JSON returned."""
    script = f"""
const fs = require("fs"), page = {json.dumps(str(PAGE))};
globalThis.importScripts = (...names) => {{ for (const n of names) Object.assign(globalThis, require(page + "/" + n)); }};
globalThis.performance = {{ timeOrigin: 0, now: () => 0 }};
const toMain = [], sent = [], drawn = [];
globalThis.postMessage = (m) => toMain.push(m);
globalThis.onmessage = null;
class FakeSocket {{ constructor(url) {{ this.url = url; this.readyState = 1; FakeSocket.last = this; }} send(x) {{ sent.push(JSON.parse(x)); }} }}
FakeSocket.OPEN = 1;
globalThis.WebSocket = FakeSocket;
require(page + "/stream_worker.js");
const {{ SceneStream, StreamDecoder, KINDS }} = require(page + "/stream.js");
const shown = new SceneStream(), truth = new StreamDecoder();
const port = {{ postMessage: (m) => {{ const f = m.frame; shown.accept(structuredClone(f), 0);
  drawn.push({{ step: f.step, behind: f.behind, extras: !!f.extras, kinds: Object.keys(f.rows), marks: f.marks === undefined ? "same" : f.marks === null ? "none" : f.marks.patch ? "patch" : "grid",
    rect: f.marks && f.marks.patch ? f.marks.patch.rect : null }}); }} }};
const buf = (i) => {{ const b = fs.readFileSync({json.dumps(str(tmp_path))} + "/" + i + ".bin"); return b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength); }};
const arrive = (i) => {{ truth.receive(buf(i)); FakeSocket.last.onmessage({{ data: buf(i) }}); }};
onmessage({{ data: {{ connect: "wss://x/ws" }} }});
onmessage({{ data: {{ drawer: port }} }});
{body}
"""
    res = subprocess.run(["node", "-e", script], capture_output=True, text=True, timeout=30)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout)


@needs_node
def test_the_stream_worker_acknowledges_every_frame_and_holds_back_all_but_the_newest_for_a_busy_drawer(tmp_path):
    """Every frame is acknowledged to the engine as soon as it is decoded; the drawer gets at most two frames
    it has not taken, then, once it takes one, the newest frame (not the next in a queue). Each message
    carries only the kinds that changed since the drawer's last one (the trees once) and, of the tracks, the
    block of cells changed since (the whole grid first); the drawer's picture is then the decoder's, cell for
    cell. (A worker that posts every frame fails the count; one that keeps a queue fails the newest step;
    one that forgets the cells of frames it held back fails the agreement.)"""
    _, blobs = worker_frames(tmp_path)
    out = run_worker(
        tmp_path,
        f"""
for (let i = 0; i < {len(blobs)}; i++) arrive(i);
const before = drawn.length;
port.onmessage({{ data: {{ got: 1 }} }});
const after = drawn.length;
port.onmessage({{ data: {{ got: 2 }} }});
const rows = KINDS.every((k) => Array.from(shown.cur.rows[k]).join() === Array.from(truth.state.rows[k]).map((v, i) =>
  v / truth.scales[k][i % truth.scales[k].length]).map((v) => Math.fround(v)).join());
const cells = Array.from(shown.marks.cells).join() === Array.from(truth.state.marks.cells).join();
console.log(JSON.stringify({{ acks: sent.map((m) => m.ack), before, after, drawn, end: drawn.length, rows, cells }}));
""",
    )
    assert out["acks"] == list(range(1, 8)), "every decoded frame is acknowledged at once"
    assert out["before"] == 2, f"{out['before']} frames given to a drawer that took none"
    assert out["after"] == 3 and out["end"] == 3
    first, second, newest = out["drawn"]
    assert first["step"] == 1 and first["extras"] and first["marks"] == "grid" and "cones" in first["kinds"]
    assert second["step"] == 2 and not second["extras"] and second["marks"] == "same"
    assert "cones" not in second["kinds"] and "capsules" in second["kinds"], second["kinds"]
    assert newest["step"] == 7 and newest["marks"] == "patch"
    assert newest["behind"] and not second["behind"], "a frame that replaced a held one is marked: the drawer is behind"
    # Steps 6 and 7 cleared (50, 50, 2, 2) and (60, 70, 1, 4); step 6 was held back and replaced by 7.
    assert newest["rect"] == [50, 50, 61, 74]
    assert out["rows"] and out["cells"], "the drawer's picture is not the decoder's"
