"""The render bench's scenes: seven puppets in a row, a crowd of fifty in rows, all framed."""

from __future__ import annotations

from puppetphone.bench.render import CROWD, demo_scene


def test_the_crowd_scene_holds_every_puppet_in_rows() -> None:
    seven, cam7 = demo_scene()
    crowd, cam = demo_scene(puppets=CROWD)
    per_puppet = len(seven.capsules) // 7
    assert len(crowd.capsules) == CROWD * per_puppet
    assert cam.distance > cam7.distance  # stepped back to see the rows


def test_frame_times_are_cpu_time_so_waiting_costs_nothing() -> None:
    import time

    from puppetphone.bench.render import cpu_frame_time

    def busy() -> None:
        end = time.process_time() + 0.003
        while time.process_time() < end:
            pass

    assert 0.003 <= cpu_frame_time(busy, frames=3) < 0.02
    assert cpu_frame_time(lambda: time.sleep(0.004), frames=3) < 0.002  # wall time is not counted


def test_the_governed_frame_settles_where_the_frames_cpu_time_says() -> None:
    """Slow frames (40 ms of CPU) end at low; quick ones (1 ms) climb to high. Broken once: feeding
    the governor a constant 0 s instead of the measured time, the slow case ended at high."""
    from puppetphone.bench.render import GovernedFrame

    slow, quick = _Levels(), _Levels()
    for renderer, cost, level in ((slow, 0.040, "low"), (quick, 0.001, "high")):
        governed = GovernedFrame(renderer, _busy([cost]))  # type: ignore[arg-type]  # the stand-in has what it uses
        for _ in range(26):
            governed()
        assert governed.governor.level == level
    assert slow.seen[0] == "medium" and slow.seen[-1] == "low"


def test_without_panda3d_the_peer_is_skipped_with_a_line(monkeypatch) -> None:
    import importlib.util

    from puppetphone.bench.render import panda3d_peer

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "panda3d" else real(name, *a))
    line = panda3d_peer()
    assert isinstance(line, str) and "Panda3D is not installed" in line


class _Levels:
    """A renderer stand-in that records the levels it is set to."""

    def __init__(self) -> None:
        self.seen: list[str] = []
        self.quality: object = None

    def set_quality(self, q) -> None:  # type: ignore[no-untyped-def]  # a Quality; the test needs no import of it
        self.seen.append(q.name)
        self.quality = q


def _busy(seconds: list[float]):  # type: ignore[no-untyped-def]  # a frame costing seconds[0] of CPU, changeable
    import time

    def frame() -> None:
        end = time.process_time() + seconds[0]
        while time.process_time() < end:
            pass

    return frame


def test_the_governed_frame_keeps_the_governor_deciding_while_it_is_timed() -> None:
    """Quick frames climb to high; when the frames turn slow the governor, still in the loop, steps down,
    and a level another measurement set in between is set back. Broken once by no longer feeding the
    governor after frame 26 (the settled level timed without it): the level stayed high and it failed;
    once by not setting the governor's level back: the levels seen were high, low, medium."""
    from engine.render.quality import QUALITIES
    from puppetphone.bench.render import GovernedFrame

    renderer, cost = _Levels(), [0.001]
    governed = GovernedFrame(renderer, _busy(cost))  # type: ignore[arg-type]  # the stand-in has what it uses
    for _ in range(26):
        governed()
    assert governed.governor.level == "high" and governed.settled_frames == 12
    cost[0] = 0.045
    renderer.set_quality(QUALITIES["low"])  # as the alternated low frames do
    for _ in range(12):
        governed()
    assert renderer.seen[-3:] == ["low", "high", "medium"]
    assert governed.governor.level == "medium" and governed.settled_frames == 33  # 7 slow frames of 12 move the median
    assert governed.settle_cpu > 7 * 0.045


def test_alternated_figures_take_turns_and_keep_their_own_times() -> None:
    """Each figure's median is its own frames' CPU time, and the order alternates round by round. Broken
    once by measuring in the same order every round: the order check failed."""
    from puppetphone.bench.render import alternated

    order: list[str] = []
    quick, slow = _busy([0.002]), _busy([0.006])

    def a() -> None:
        order.append("a")
        quick()

    def b() -> None:
        order.append("b")
        slow()

    times = alternated({"a": a, "b": b}, rounds=3, per_round=2)
    assert 0.002 <= times["a"] < 0.005 <= 0.006 <= times["b"] < 0.012
    runs = [order[0]] + [x for i, x in enumerate(order[1:], 1) if x != order[i - 1]]
    assert runs == ["a", "b", "a", "b"]  # a b | b a | a b


def test_the_played_window_frame_is_the_runners_draw_of_the_session_after_its_steps() -> None:
    """``render_fps_1000_puppets_play`` times what a window draws: the session's drawing (every puppet's
    capsules and the HUD, whose lines name what the crowd is doing) into a new scene each frame, seen by
    the session's camera, waited for; after the steps of play it was given. Broken once by drawing the game
    without the overlay (the old figure's frame): the scene held no HUD line and it failed; once by reusing one scene without
    clearing it: the second frame held two crowds."""
    from games.sandbox import camera
    from puppetphone.bench.render import played_window_frame

    viewer = _Viewer()
    frame = played_window_frame(viewer, 6, 5)  # type: ignore[arg-type]  # the stand-in has what it uses
    frame()
    frame()
    assert viewer.finished == 2
    for capsules, distance, texts in viewer.drawn:
        assert capsules == 6 * 21 and distance == camera().distance
        assert "frame 5" in texts[0] and "and 2 more: " in "\n".join(texts)
        assert any(line.startswith("[idle] mouse") for line in texts)  # the window's own source


class _Viewer:
    """A viewer stand-in: records what each frame drew and how often the frame was waited for."""

    size = (1280, 720)

    def __init__(self) -> None:
        self.camera: object = None
        self.drawn: list[tuple[int, float, list[str]]] = []
        self.finished = 0
        self.target = self

    @property
    def ctx(self) -> _Viewer:
        return self

    def __enter__(self) -> None:
        return None

    def __exit__(self, *exc: object) -> None:
        return None

    def finish(self) -> None:
        self.finished += 1

    def draw(self, scene) -> None:  # type: ignore[no-untyped-def]  # a RenderScene
        self.drawn.append((len(scene.capsules), self.camera.distance, [t.text for t in scene.texts]))  # type: ignore[attr-defined]  # an OrbitCamera
