"""Renderer frame rate at 1280x720 on the headless target (Mesa llvmpipe on these machines).

The scene is the one the issue names: seven puppets (17 joints, 21 capsules each with
their tips) in varied poses, twenty snowballs, falling snow, a curve, overlay text and
one outlined puppet, all with shadows; and a crowd of fifty puppets
(``render_fps_50_puppets``). The baseline is the same frame without any
object (sky and snowy ground only), measured in the same run: it is the fixed cost of
filling 1280x720 pixels that every frame pays, whatever the scene holds.

The issue's figures are in process CPU time (every llvmpipe thread counted), the median
of 3 repeats of several frames each (:func:`cpu_frame_time`):

- ``render_fps_100_puppets``: a crowd of 100 at quality ``low`` (the level a laptop
  without a GPU falls to), against Panda3D drawing 100 walking skinned actors off-screen
  on the same llvmpipe (:mod:`puppetphone.bench.render_panda`, the ``[peers]`` extra), and the 30 fps
  goal; without Panda3D a line says the peer was skipped.
- ``render_fps_1000_puppets_play``: the frame a window of ``play sandbox --puppets 1000`` (mouse
  source, seed 0) draws at ``low``, the level its governor settles on (:func:`played_window_frame`):
  the runner's draw of the session, that is the game's ``draw_world`` (the crowd's capsules from
  its columns, the height cues) and the HUD overlay (its lines name what the 1000 puppets are
  doing) into a new scene, then the renderer through the window's own camera (the sandbox's) at
  1280x720, the 3-D scene at 640x360 scaled up. It is timed after :data:`PLAY_STEPS` steps of play,
  when the crowd has walked into that view as a player sees it after 20 s (3,000 of the 21,000
  capsules in it, about 140 puppets, drawn as impostors over one another towards the horizon; the
  rest culled; the crowd goes on filling the view: 6,500 capsules at 2,400 steps), in process CPU
  time (the llvmpipe threads counted), the median of 3 repeats of 4 frames. The
  shadows are drawn every frame, as they are while the crowd walks. Against 10 fps, the rate
  down to which a window keeps game time; the steps between two frames are not in it
  (``crowd_step_ms_1000``), nor the window's swap.
- ``render_fps_snowman_auto``: the snowman frame with the quality governor in the loop, as a
  player's ``auto`` has it (:class:`GovernedFrame`): it starts at ``medium`` and decides from each
  frame's CPU time; after its first 40 frames the frames are timed with it still deciding, in
  rounds alternated with ``render_fps_snowman_low`` (:func:`alternated`), so that two figures of
  the same drawing are not a minute of other people's load apart. ``auto_settle_frames_snowman``:
  the frames it took to reach its level (they are a player's first second at a level the machine
  cannot hold; the level and their CPU time are printed).
- ``render_fps_skinned_<n>``: 1, 10 and 100 skinned glTF characters against as many
  mannequins in the same poses (:mod:`puppetphone.bench.render_skinned`).
- ``render_fps_snowman_<quality>``: the loaded snowman game's frame at each level,
  against the 30 fps goal; ``sky_ground_ms_<quality>``: the same frame with nothing in
  it, against a clear of the screen, measured in the same run (the floor of any frame);
  ``flat_fill_ms_1280x720``: a clear plus one flat-colour triangle over the screen, the
  least any per-pixel pass costs on this rasteriser (what a drawn sky and ground can
  approach, not beat). ``sky_ground_added_ms_<quality>``: what the sky and ground add to a frame
  at that level, against a clear of the screen: the empty frame less a frame at that level with
  nothing drawn at all, sky and ground left out (:meth:`~engine.render.renderer.Renderer.draw_floor`:
  the level's buffer cleared and, at ``low`` and ``medium``, scaled up over the screen; its time is in
  the baseline's label). The scale-up is a per-pixel pass over 1280x720 (at least ``flat_fill``)
  paid by every frame at those levels whatever it holds, so the empty frame at them cannot match a
  clear of the screen; the sky and ground themselves can.
  At ``low`` and ``medium`` the camera stands still, as the snowman game's does, so the sky
  and ground are drawn once and copied into each frame (:mod:`engine.render.env_cache`: a
  memory copy of the smaller buffer's colour and depth, ~0.14 ms at 640x360 against ~0.6 ms
  for its clear). What the empty frame still pays is the frame's Python (uniforms, culling of
  nothing: ~0.8 ms) and the scale-up of that buffer over 1280x720 pixels (~3 ms on llvmpipe's
  linear path, :mod:`engine.render.bgra`), which alone writes as many pixels as the clear it is
  compared with. In a window the scale-up writes into the window's own framebuffer
  (:mod:`engine.render.window`); here it writes into the off-screen frame.
  ``sky_ground_moving_ms_low`` and ``_high``: the same empty frame with the camera turning a
  little every frame, so the view is drawn anew each time (at low: clear, ground mesh at
  640x360, ~2.2 ms, copy kept; at high: the per-pixel snow at 1280x720, its near detail only
  on the rings within reach of it, :meth:`engine.render.environment.Environment.ground_draws`).
  ``high`` shades the snow per pixel; without a caster it reads no shadow mask and is kept like
  the other levels' (so ``sky_ground_ms_high`` is a copy), with one (the snowman frame) it reads
  the moving shadows and is drawn every frame: ``sky_ground_moving_ms_high`` is what that costs.

These machines are shared, so wall-clock frame rates swing with other people's load. The
bench therefore also reads each thread's CPU time per frame from ``/proc`` (Linux): the
main thread (Python, vertex work, binning) runs in series with the busiest llvmpipe
rasteriser thread, so ``main + busiest`` is the frame time the same work takes when the
cores are free (``fps_unloaded_1280x720``).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from puppetphone.bench.figures import Figure, median_time

if TYPE_CHECKING:
    from engine.camera import Camera, OrbitCamera
    from engine.render import RenderScene
    from engine.render.renderer import Renderer
    from engine.render.viewer import Viewer

__all__ = [
    "run",
    "demo_scene",
    "unloaded_frame_time",
    "cpu_frame_time",
    "quality_figures",
    "played_window_frame",
    "GovernedFrame",
    "alternated",
]

WIDTH, HEIGHT = 1280, 720
_ROW = 10  # puppets per row of the scene (seven stand in one row, a crowd of fifty in five)
CROWD = 50
BIG_CROWD = 100
PLAY_CROWD = 1000
PLAY_STEPS = 1200
"""Steps of play before the window's frame is timed (20 s of game time): the wanderers have left their grid
behind the camera and fill its view, about 140 of them in it, as the window shows them 20 s after it opens."""
COLORS = (
    (0.85, 0.3, 0.25),
    (0.25, 0.5, 0.85),
    (0.3, 0.7, 0.35),
    (0.9, 0.7, 0.2),
    (0.6, 0.35, 0.75),
    (0.2, 0.7, 0.7),
    (0.85, 0.5, 0.6),
)


def demo_scene(puppets: int = 7, snowballs: int = 20, seed: int = 1) -> tuple[RenderScene, OrbitCamera]:
    """The benchmark scene and a camera that frames it."""
    from engine import quat
    from engine.camera import OrbitCamera
    from engine.fk import forward_kinematics
    from engine.humanoid import humanoid_skeleton
    from engine.render import RenderScene, puppet_capsules

    rng = np.random.default_rng(seed)
    sk = humanoid_skeleton()
    scene = RenderScene()
    per_row = min(puppets, _ROW)
    for i in range(puppets):
        rots = quat.exp(rng.normal(scale=0.25, size=(sk.num_joints, 3)))
        rots[0] = quat.from_axis_angle([0, 1, 0], rng.uniform(-1, 1))
        col, row = i % per_row, i // per_row
        root = np.array([(col - (per_row - 1) / 2) * 1.1, 0.95, -abs(col - (per_row - 1) / 2) * 0.5 - 1.3 * row])
        pos, rot = forward_kinematics(sk, root, rots)
        a, b, r, _ = puppet_capsules(sk, pos, rot)
        scene.add_capsules(a, b, r, COLORS[i % len(COLORS)], outline=(i == puppets // 2))
    radii = rng.uniform(0.15, 0.45, snowballs)
    centres = np.c_[rng.uniform(-6, 6, snowballs), radii, rng.uniform(-4, 2, snowballs)]  # resting on the snow
    scene.add_spheres(centres, radii)
    t = np.linspace(0, 6, 50)
    scene.add_polyline(np.c_[np.linspace(-3, 3, 50), 0.35 + 0.25 * np.sin(t), np.full(50, 1.5)], (0.9, 0.2, 0.1), 3)
    scene.add_points(rng.uniform([-8, 0, -8], [8, 4, 4], (300, 3)), 0.03)
    scene.add_text("fps 60.0")
    scene.add_text("state: walk")
    rows = -(-puppets // per_row)
    camera = OrbitCamera(
        target=np.array([0.0, 0.8, -0.65 * (rows - 1)]), yaw=0.35, pitch=0.28, distance=7.5 + 2.0 * (rows - 1)
    )
    return scene, camera


def _thread_cpu() -> dict[str, float]:
    """CPU seconds used so far by each thread of this process (empty where /proc is missing)."""
    out: dict[str, float] = {}
    tick = os.sysconf("SC_CLK_TCK")
    try:
        tids = os.listdir("/proc/self/task")
    except OSError:
        return out
    for tid in tids:
        try:
            with open(f"/proc/self/task/{tid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        out[tid] = (int(fields[11]) + int(fields[12])) / tick  # utime + stime
    return out


def played_window_frame(viewer: Viewer, puppets: int = PLAY_CROWD, steps: int = PLAY_STEPS) -> Callable[[], None]:
    """The frame a window of ``play sandbox --puppets N`` draws after ``steps`` steps of play, drawn the way
    :meth:`engine.runner.Runner.draw` draws it: the session's own draw (the game's drawing and the HUD
    overlay, sized for ``viewer``) into a new scene, then ``viewer`` through the session's camera, waited for."""
    from engine.render.scene import RenderScene
    from input.hub import InputHub
    from input.mouse import MouseSource
    from puppetphone.session import build_activity

    activity = build_activity(
        "sandbox", 0, InputHub([MouseSource()]), options={"scene": "empty", "puppets": str(puppets)}
    )
    for _ in range(steps):
        activity.step()

    def frame() -> None:
        scene = RenderScene()
        activity.draw(scene, 0.5, viewer.size)
        viewer.camera = activity.camera
        viewer.draw(scene)
        with viewer.target.ctx:
            viewer.target.ctx.finish()

    return frame


def unloaded_frame_time(frame: Callable[[], object], frames: int = 40) -> float | None:
    """Seconds per frame if the cores were free: main thread + busiest other thread CPU."""
    before = _thread_cpu()
    for _ in range(frames):
        frame()
    after = _thread_cpu()
    if not after:
        return None
    main = str(os.getpid())
    used = {t: (after[t] - before.get(t, 0.0)) / frames for t in after}
    workers = [v for t, v in used.items() if t != main]
    return used.get(main, 0.0) + (max(workers) if workers else 0.0)


_FILL_VS = """#version 330 core
void main() { gl_Position = vec4(vec2((gl_VertexID << 1) & 2, gl_VertexID & 2) * 2.0 - 1.0, 0.5, 1.0); }
"""
_FILL_FS = """#version 330 core
out vec4 f_color;
void main() { f_color = vec4(0.8, 0.85, 0.9, 1.0); }
"""


def cpu_frame_time(frame: Callable[[], object], frames: int = 6, repeats: int = 3) -> float:
    """Median over ``repeats`` of the process CPU seconds per frame of ``frame`` (after two warm-up frames).

    Process CPU time counts the main thread and every rasteriser thread, so it does not
    swing with other people's load on a shared machine as wall time does.
    """
    import time

    frame()
    frame()
    samples = []
    for _ in range(repeats):
        t0 = time.process_time()
        for _ in range(frames):
            frame()
        samples.append((time.process_time() - t0) / frames)
    return float(np.median(samples))


def panda3d_peer() -> tuple[float, int] | str:
    """Panda3D's 100 walking actors (:mod:`puppetphone.bench.render_panda`, in its own process): ``(CPU seconds per
    frame, triangles)``, or the line saying why it was skipped."""
    import importlib.util
    import subprocess
    import sys

    if importlib.util.find_spec("panda3d") is None:
        return "render: [peers] Panda3D is not installed (pip install panda3d): render_fps_100_puppets vs 30 fps only"
    done = subprocess.run(
        [sys.executable, "-m", "puppetphone.bench.render_panda"],
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    lines = done.stdout.split()
    if done.returncode != 0 or len(lines) < 2:
        return f"render: [peers] the Panda3D peer failed ({done.returncode}): {done.stderr.strip()[-200:]}"
    return float(lines[-2]), int(lines[-1])


class GovernedFrame:
    """``frame`` drawn at the level a live :class:`~engine.render.quality.QualityGovernor` picks from
    each frame's CPU time, as the runner's ``auto`` does: the governor stays in the loop for every
    frame timed, so a level it changes to mid-measurement is what the figure counts.

    It starts where a player's game starts (``medium``); :attr:`settled_frames` and
    :attr:`settle_cpu` say how many frames, and how much CPU, went by up to its last change
    (the frames a player sees at a level the machine cannot hold).
    """

    def __init__(self, renderer: Renderer, frame: Callable[[], object]) -> None:
        from engine.render.quality import QualityGovernor

        self.renderer, self.frame = renderer, frame
        self.governor = QualityGovernor("auto")
        self.frames, self.cpu = 0, 0.0
        self.settled_frames, self.settle_cpu = 0, 0.0
        renderer.set_quality(self.governor.quality)

    def __call__(self) -> None:
        import time

        if self.renderer.quality is not self.governor.quality:  # another measurement drew in between
            self.renderer.set_quality(self.governor.quality)
        t0 = time.process_time()
        self.frame()
        took = time.process_time() - t0
        self.frames, self.cpu = self.frames + 1, self.cpu + took
        if self.governor.frame(took):
            self.renderer.set_quality(self.governor.quality)
            self.settled_frames, self.settle_cpu = self.frames, self.cpu


def alternated(frames: dict[str, Callable[[], object]], rounds: int = 3, per_round: int = 6) -> dict[str, float]:
    """Process CPU seconds per frame of each of ``frames``, measured in rounds that alternate them
    (``a b``, ``b a``, ...): the median over rounds of :func:`cpu_frame_time` of ``per_round`` frames.

    Figures compared with each other are measured this way, in the same minutes: on a shared
    machine the load changes from one minute to the next, and a figure measured a minute after
    another carries that change (the automatic level, once measured last, read 27 fps against
    low's 33 for the same frame drawn the same way).
    """
    samples: dict[str, list[float]] = {name: [] for name in frames}
    names = list(frames)
    for i in range(rounds):
        for name in names if i % 2 == 0 else names[::-1]:
            samples[name].append(cpu_frame_time(frames[name], frames=per_round, repeats=1))
    return {name: float(np.median(v)) for name, v in samples.items()}


def quality_figures() -> list[Figure]:
    """The issue's figures: the snowman frame per quality level, sky+ground vs a clear, 100 puppets at low."""
    import sys

    from engine.render.quality import QUALITIES
    from engine.render.renderer import Renderer
    from engine.render.scene import RenderScene
    from engine.render.target import make_target
    from engine.render.viewer import Viewer
    from games.snowman.game import GAME
    from input.hub import InputHub
    from puppetphone.bench.snowman import loaded_app
    from puppetphone.overlay import draw_overlay

    app, hub = loaded_app(), InputHub()
    target = make_target(True, WIDTH, HEIGHT)
    renderer = Renderer(target.ctx)
    scene, empty, camera = RenderScene(), RenderScene(), GAME.camera()
    empty.ground.grid = False  # the snowman field's ground (no grid lines)
    crowd, crowd_camera = demo_scene(puppets=BIG_CROWD)

    def draw(s: RenderScene, cam: Camera) -> None:
        renderer.render(s, cam, target.begin())
        target.end()
        target.ctx.finish()

    def game_frame() -> None:
        scene.clear()
        GAME.draw(app.world, scene, 1.0)
        draw_overlay(scene, app.world, GAME, hub, 60.0, False)
        draw(scene, camera)

    def clear() -> None:
        target.begin().clear(*empty.horizon_color, 1.0, depth=1.0)
        target.end()
        target.ctx.finish()

    ctx = target.ctx
    flat = ctx.program(vertex_shader=_FILL_VS, fragment_shader=_FILL_FS)
    fill_vao = ctx.vertex_array(flat, [])

    def fill() -> None:
        """A clear, then one flat-colour triangle over the screen: the floor of any per-pixel pass."""
        target.begin().clear(0.5, 0.5, 0.5, 1.0, depth=1.0)
        fill_vao.render(vertices=3)
        target.end()
        ctx.finish()

    figures = []
    try:
        t_clear, t_fill = cpu_frame_time(clear), cpu_frame_time(fill)
        figures.append(
            Figure("render", "flat_fill_ms_1280x720", t_fill * 1e3, "ms", "clear of the screen", t_clear * 1e3)
        )
        game_fps: dict[str, float] = {}
        env_ms: dict[str, float] = {}
        floor_ms: dict[str, float] = {}

        def level_floor() -> None:
            """A frame at the current level with nothing in it, not even the sky and ground (see the docstring)."""
            renderer.draw_floor(empty, target.begin())
            target.end()
            ctx.finish()

        for name, quality in QUALITIES.items():
            renderer.set_quality(quality)
            if name != "low":  # low is measured with auto, below, in alternation
                game_fps[name] = 1.0 / cpu_frame_time(game_frame)
            env_ms[name] = cpu_frame_time(lambda: draw(empty, camera)) * 1e3
            floor_ms[name] = cpu_frame_time(level_floor) * 1e3
        renderer.set_quality(QUALITIES["low"])
        turning, frames_drawn = GAME.camera(), [0]

        def moving_empty() -> None:
            """The empty frame with the camera turned a milliradian from the last frame's: a new view."""
            frames_drawn[0] += 1
            turning.yaw = camera.yaw + 1e-3 * (frames_drawn[0] % 2)
            draw(empty, turning)

        t_moving = cpu_frame_time(moving_empty)
        renderer.set_quality(QUALITIES["high"])
        t_moving_high = cpu_frame_time(moving_empty)
        renderer.set_quality(QUALITIES["low"])
        # auto: a player's first frames (from medium, the governor deciding), then the same frame at low
        # and under the governor in alternating rounds, so the two figures share the machine's minutes.
        governed = GovernedFrame(renderer, game_frame)
        for _ in range(40):
            governed()

        def at_low() -> None:
            renderer.set_quality(QUALITIES["low"])
            game_frame()

        both = alternated({"low": at_low, "auto": governed}, rounds=5, per_round=4)  # 20 frames each, 5 turns
        game_fps["low"], game_fps["auto"] = 1.0 / both["low"], 1.0 / both["auto"]
        clear_ms = t_clear * 1e3
        for name in QUALITIES:
            figures.append(Figure("render", f"render_fps_snowman_{name}", game_fps[name], "fps", "30 fps goal", 30.0))
            figures.append(
                Figure("render", f"sky_ground_ms_{name}", env_ms[name], "ms", "clear of the screen", clear_ms)
            )
            figures.append(
                Figure(
                    "render",
                    f"sky_ground_added_ms_{name}",
                    env_ms[name] - floor_ms[name],
                    "ms",
                    f"clear of the screen (a {name} frame with nothing drawn: {floor_ms[name]:.3g} ms)",
                    clear_ms,
                )
            )
        for name, t in (("low", t_moving), ("high", t_moving_high)):
            figures.append(
                Figure("render", f"sky_ground_moving_ms_{name}", t * 1e3, "ms", "clear of the screen", clear_ms)
            )
        figures.append(Figure("render", "render_fps_snowman_auto", game_fps["auto"], "fps", "30 fps goal", 30.0))
        figures.append(Figure("render", "auto_settle_frames_snowman", float(governed.settled_frames), "frames"))
        print(
            f"render: auto settled on {governed.governor.level} for the snowman frame after "
            f"{governed.settled_frames} frames ({governed.settle_cpu:.2f} s of CPU) and stayed there for the "
            f"{governed.frames - governed.settled_frames} frames after, each timed with the governor in the loop",
            file=sys.stderr,
        )
        renderer.set_quality(QUALITIES["low"])
        t_crowd = cpu_frame_time(lambda: draw(crowd, crowd_camera), frames=3)
        t_play = cpu_frame_time(played_window_frame(Viewer(target, renderer=renderer)), frames=4)
    finally:
        fill_vao.release()
        flat.release()
        renderer.release()
        target.close()
    figures.append(
        Figure(
            "render",
            f"render_fps_{PLAY_CROWD}_puppets_play",
            1.0 / t_play,
            "fps",
            "10 fps: a window keeps game time down to it",
            10.0,
        )
    )
    peer = panda3d_peer()
    if isinstance(peer, str):
        print(peer, file=sys.stderr)
        figures.append(Figure("render", f"render_fps_{BIG_CROWD}_puppets", 1.0 / t_crowd, "fps", "30 fps goal", 30.0))
    else:
        figures.append(
            Figure(
                "render",
                f"render_fps_{BIG_CROWD}_puppets",
                1.0 / t_crowd,
                "fps",
                f"Panda3D, {BIG_CROWD} walking actors ({peer[1]} triangles, unlit, no shadows)",
                1.0 / peer[0],
            )
        )
        print("render: render_fps_100_puppets also against the 30 fps goal", file=sys.stderr)
    return figures


def run() -> list[Figure]:
    """Median frame times of the demo scene and of the empty baseline frame, then :func:`quality_figures`."""
    from engine.render import RenderScene, Viewer

    viewer = Viewer.create(True, WIDTH, HEIGHT, samples=0)
    try:
        scene, camera = demo_scene()
        viewer.camera = camera
        empty = RenderScene()

        def frame(s: RenderScene) -> None:
            viewer.draw(s)
            with viewer.target.ctx:  # wait for the frame in the viewer's own context, or nothing waits
                viewer.target.ctx.finish()

        t_scene = median_time(lambda: frame(scene), repeats=15, min_time=0.0)
        t_empty = median_time(lambda: frame(empty), repeats=15, min_time=0.0)
        t_free = unloaded_frame_time(lambda: frame(scene))
        crowd, viewer.camera = demo_scene(puppets=CROWD)
        t_crowd = median_time(lambda: frame(crowd), repeats=9, min_time=0.0)
    finally:
        viewer.close()
    figures = [
        Figure("render", "frame_ms_1280x720", t_scene * 1e3, "ms", "sky+ground only frame", t_empty * 1e3),
        Figure("render", "fps_1280x720", 1.0 / t_scene, "fps", "30 fps target", 30.0),
    ]
    if t_free:
        figures.append(Figure("render", "fps_unloaded_1280x720", 1.0 / t_free, "fps", "30 fps target", 30.0))
    figures.append(Figure("render", "capsules_drawn", float(len(scene.capsules)), "count"))
    figures.append(Figure("render", f"render_fps_{CROWD}_puppets", 1.0 / t_crowd, "fps", "30 fps target", 30.0))
    from puppetphone.bench.render_skinned import run as skinned_figures

    return figures + quality_figures() + skinned_figures()
