"""The one frame loop: every session — play, replay, the authoring scenes, demos — runs here.

A session hands the runner an :class:`Activity`: something that steps at a fixed ``dt``
and draws itself. The runner owns everything around it:

- the **render target** (a window, or an EGL off-screen buffer with ``headless``);
- the **clock**: in a window, real elapsed time goes through a
  :class:`~engine.clock.FixedStepClock` (the scene is drawn every display frame,
  interpolated with its ``alpha``); headless, steps run back to back, or paced to wall
  time (:class:`~engine.pacing.RealTimePacer`) when a live device drives the session.
  Either way the activity's own time is ``steps × dt``: at 8 rendered frames a second a
  3 s countdown still takes 3 s, and a performer's tempo is kept. A slow frame is followed
  by as many steps as it lasted (frames are dropped, not time) up to
  :data:`MAX_FRAME_TIME`; only a longer stall drops time, and then the window says so
  (:class:`~engine.pacing.TimeKeeper`) until the game keeps time again. The same bound
  holds the wall time a frame's steps may take: when the steps themselves are slower
  than real time (1000 puppets on a slow machine), a frame runs the steps that fit in
  :data:`MAX_FRAME_TIME` and drops the rest, rather than run all that are due and leave
  the window still for seconds while falling further behind. How many steps
  run per frame varies; each step is the same fixed ``dt`` with its own recorded input,
  so the simulation never depends on the frame rate;
- the **drawing quality** (:mod:`engine.render.quality`): ``--quality`` fixes it, or
  ``auto`` lets the measured drawing time choose (with the two steps a 30 fps frame must
  also run, not the frame's whole loop time); ``G`` cycles low, medium, high, auto;
- the **event stack**: window events go to the handlers pushed last first (tools and
  overlays before the game, as in pyglet's handler stack); a handler that returns true
  consumes the event. The runner's own handler sits at the bottom: Esc and closing the
  window quit, ``P`` pauses, ``.`` single-steps while paused, ``G`` changes the quality;
- the **common options**: ``--headless --frames --screenshot --screenshot-at``, window
  size and title.

``--frames N`` means N simulation steps, in a window too (catch-up never overshoots).
"""

from __future__ import annotations

import math
import os
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

from engine import jit
from engine.camera import Camera
from engine.clock import FixedStepClock
from engine.pacing import RealTimePacer, TimeKeeper
from engine.render.scene import RenderScene
from engine.render.window import INVISIBLE_DRIVERS, NoDisplayError

__all__ = [
    "Activity",
    "EventHandler",
    "NoDisplayError",
    "RunOptions",
    "RunResult",
    "Runner",
    "check_display",
    "MAX_FRAME_TIME",
]

#: Real time a window frame may add at most (a stall drops time beyond this): 2.5 frames at 10 fps.
MAX_FRAME_TIME = 0.25
#: Wall seconds between two writes of ``RunOptions.hud_dump``.
HUD_DUMP_INTERVAL = 0.1
_NOTE_SECONDS = 2.0
_STARTING = "starting: a first start after an install compiles the engine's kernels (about half a minute)"
"""The window's first frame, drawn before the first step: on a machine with the kernels cached the next
frame follows at once; on a first start it stays while the first steps compile them."""
_COMPILE_NOTE = 0.25
"""Seconds of compiling in one frame's steps from which the window says so."""
_ONCE = "a first start after an install, once"


class Activity(Protocol):
    """What the runner runs: fixed steps of ``dt`` and a drawing of the current state."""

    dt: float

    @property
    def camera(self) -> Camera:
        """The camera the window shows (the runner only reads it: a game's may be a property)."""
        ...

    def step(self) -> None:
        """Advance one fixed step."""
        ...

    def draw(self, scene: RenderScene, alpha: float, size: tuple[int, int]) -> None:
        """Fill ``scene`` with the current state (``alpha``: fraction of the next step)."""
        ...

    def finished(self) -> bool:
        """Whether the activity has ended on its own (a replay ran out, a verify failed)."""
        ...


class EventHandler(Protocol):
    """A layer of the event stack."""

    def on_event(self, event: Any, runner: Runner) -> bool:
        """Handle a pygame event; return true to stop it reaching the layers below."""
        ...


def check_display() -> None:
    """Refuse to open an invisible window: no ``DISPLAY``/``WAYLAND_DISPLAY``, or a dummy driver.

    Without a display SDL falls back to its offscreen or dummy driver and the session
    would run, unseen, until killed.
    """
    driver = os.environ.get("SDL_VIDEODRIVER", "").lower()
    if driver in INVISIBLE_DRIVERS:
        raise NoDisplayError(
            f"no display (SDL_VIDEODRIVER={driver}): a window cannot be shown here; use --headless to run without one"
        )
    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise NoDisplayError(
            "no display (DISPLAY and WAYLAND_DISPLAY are unset): a window cannot be shown here; "
            "use --headless to run without one"
        )


@dataclass
class RunOptions:
    """The options every session shares.

    Attributes:
        headless: render off-screen (EGL); no window, no events.
        frames: stop after this many simulation steps (``None``: until the activity
            finishes or the window closes).
        screenshot: write the final frame here (PNG or JPEG by suffix).
        screenshot_at: write ``screenshot`` after this step instead of at the end.
        pace: headless only — hold each step to wall time (a live device drives it).
        hud_dump: write the text of every drawn frame's overlay here (replaced atomically a few
            times a second): what the HUD says, for scripts and tests that drive a real window.
        quality: ``low``, ``medium``, ``high`` or ``auto`` (:mod:`engine.render.quality`;
            headless, ``auto`` is ``high``: nobody waits for those frames).
    """

    headless: bool = False
    frames: int | None = None
    screenshot: Path | None = None
    screenshot_at: int | None = None
    width: int = 1280
    height: int = 720
    title: str = "PuppetPhone"
    pace: bool = False
    hud_dump: Path | None = None
    quality: str = "auto"

    def __post_init__(self) -> None:
        from engine.render.quality import parse_quality

        self.quality = parse_quality(self.quality)
        if self.frames is not None and self.frames < 0:
            raise ValueError(f"frames must be zero or more, not {self.frames}")
        if self.screenshot_at is not None and self.screenshot_at < 0:
            raise ValueError(f"screenshot step must be zero or more, not {self.screenshot_at}")
        if self.screenshot_at is not None and self.screenshot is None:
            raise ValueError("a screenshot step needs a screenshot file")


@dataclass
class RunResult:
    """How a run ended."""

    steps: int
    quit: bool = False
    screenshot: Path | None = None


class _RateMeter:
    """Frames per second of wall time over half-second windows (the rate so far until the first one ends).

    Headless, a frame is a step: the HUD of a screenshot shows how fast the run went, not 0.
    """

    WINDOW = 0.5

    def __init__(self, now: float) -> None:
        self._t0, self._frames, self.rate = now, 0, 0.0
        self._measured = False

    def tick(self, now: float) -> None:
        """One more frame, at ``now``."""
        self._frames += 1
        elapsed = now - self._t0
        if elapsed >= self.WINDOW:
            self.rate, self._frames, self._t0, self._measured = self._frames / elapsed, 0, now, True
        elif not self._measured and elapsed >= 0.1 * self.WINDOW:  # the first few frames alone say little
            self.rate = self._frames / elapsed


class _BaseKeys:
    """The bottom of the event stack: quit, pause and single step."""

    def on_event(self, event: Any, runner: Runner) -> bool:
        import pygame

        if event.type == pygame.QUIT or (event.type == pygame.KEYDOWN and event.key == pygame.K_ESCAPE):
            runner.stop()
            return True
        if event.type == pygame.KEYDOWN and event.key in (pygame.K_p, pygame.K_PERIOD):
            clock = runner.clock
            assert clock is not None  # window events come only inside run(), which sets the clock first
            if event.key == pygame.K_p:
                clock.resume() if clock.paused else clock.pause()
                return True
            if clock.paused:
                clock.request_step()
                return True
        if event.type == pygame.KEYDOWN and event.key == pygame.K_g:
            runner.cycle_quality()
            return True
        return False


class Runner:
    """Runs an :class:`Activity` in a window or headless; see the module docstring.

    Args:
        options: the shared options.
        clock: the fixed-step clock (an app's, so its pause state is what the overlay
            shows); a new one at the activity's ``dt`` when omitted.
        wall: the wall clock (injectable for tests of the tempo).
    """

    def __init__(
        self, options: RunOptions, clock: FixedStepClock | None = None, wall: Callable[[], float] = time.perf_counter
    ) -> None:
        self.options = options
        self.clock = clock
        self.handlers: list[EventHandler] = [_BaseKeys()]
        self.fps = 0.0
        self.viewer: Any = None
        self._wall = wall
        self._stopped = False
        self._shot: Path | None = None
        self._hud_at = -math.inf
        from engine.render.quality import QualityGovernor

        self.quality = QualityGovernor("high" if options.headless and options.quality == "auto" else options.quality)
        self.keeper = TimeKeeper(MAX_FRAME_TIME)
        self._step_cost = 0.0
        """Wall seconds of one simulation step, as the last window frame that stepped measured them."""
        self._note: tuple[str, float] | None = None
        self._compile_told = False

    # -- event stack ---------------------------------------------------------------------
    def push_handlers(self, handler: EventHandler) -> None:
        """Put a layer on top of the stack: it sees events before every layer below."""
        self.handlers.append(handler)

    def pop_handlers(self, handler: EventHandler) -> None:
        """Remove a layer."""
        self.handlers.remove(handler)

    def dispatch(self, event: Any) -> bool:
        """Offer ``event`` to the layers, top first; true if one consumed it."""
        return any(handler.on_event(event, self) for handler in reversed(self.handlers))

    def stop(self) -> None:
        """End the run after the current frame."""
        self._stopped = True

    @property
    def size(self) -> tuple[int, int]:
        """The target's size in pixels."""
        return self.viewer.size if self.viewer is not None else (self.options.width, self.options.height)

    # -- running -------------------------------------------------------------------------
    def open(self) -> None:
        """Open the render target (a window needs a display: :class:`NoDisplayError`)."""
        if self.viewer is not None:
            return
        from engine.render.viewer import Viewer

        if not self.options.headless:
            check_display()
        o = self.options
        self.viewer = Viewer.create(
            headless=o.headless, width=o.width, height=o.height, **({} if o.headless else {"title": o.title})
        )
        self.viewer.renderer.reuse_shadows = True  # a still scene (paused, idle) skips its shadow pass
        self._apply_quality()

    def cycle_quality(self) -> None:
        """The quality key: the next of low, medium, high, auto, said on screen for a moment."""
        mode = self.quality.cycle()
        self._apply_quality()
        self.keeper.restart()
        level = "" if mode != "auto" else f" (now {self.quality.level})"
        self._note = (f"quality: {mode}{level}", self._wall() + _NOTE_SECONDS)

    def _apply_quality(self) -> None:
        if self.viewer is None:
            return
        ctx = getattr(self.viewer.target, "ctx", None)
        if ctx is None:  # a stand-in viewer without GL (tests)
            self.viewer.renderer.set_quality(self.quality.quality)
            return
        with ctx:
            self.viewer.renderer.set_quality(self.quality.quality)

    def run(self, activity: Activity) -> RunResult:
        """Run ``activity`` until it finishes, ``frames`` steps ran, or the user quits."""
        if self.clock is None:
            self.clock = FixedStepClock(dt=activity.dt)
        self.clock.max_steps = max(self.clock.max_steps, math.ceil(MAX_FRAME_TIME / activity.dt))
        self._stopped = False
        if self.options.headless:
            steps = self._run_headless(activity)
        else:
            self.open()
            steps = self._run_window(activity)
        if self.options.screenshot is not None and self._shot is None:
            self._take_screenshot(activity)
        return RunResult(steps=steps, quit=self._stopped, screenshot=self._shot)

    def _limit(self, steps: int) -> int:
        """Steps still allowed by ``frames`` (a large number without it)."""
        frames = self.options.frames
        return sys.maxsize if frames is None else max(frames - steps, 0)

    def _after_step(self, activity: Activity, steps: int) -> None:
        if self.options.screenshot_at is not None and steps == self.options.screenshot_at:
            self._take_screenshot(activity)

    def _run_headless(self, activity: Activity) -> int:
        # A live controller's reading may start its step up to half a step early (RealTimePacer's wake).
        wake = getattr(activity, "input_wake", None)
        pacer = RealTimePacer(activity.dt, clock=self._wall, wake=wake) if self.options.pace else None
        steps = 0
        meter = _RateMeter(self._wall())
        if self.options.screenshot_at == 0:
            self._take_screenshot(activity)
        while self._limit(steps) > 0 and not activity.finished() and not self._stopped:
            if pacer is not None:
                pacer.wait()
            activity.step()
            steps += 1
            meter.tick(self._wall())
            self.fps = meter.rate
            self._after_step(activity, steps)
        return steps

    def _run_window(self, activity: Activity) -> int:
        assert self.clock is not None
        last = self._wall()
        steps = 0
        meter = _RateMeter(last)
        compiled_seen = compiled_at_start = jit.compile_seconds()
        self._note = (_STARTING, math.inf)  # on screen while the first step runs (see _STARTING)
        while not self._stopped and self._limit(steps) > 0 and not activity.finished():
            for event in self.viewer.poll_events():
                self.dispatch(event)
            if getattr(self.viewer.target, "closed", False):
                self._stopped = True
            if self._stopped:
                break
            now = self._wall()
            elapsed, dropped_before = now - last, self.clock.dropped_time
            compiling = jit.compile_seconds() - compiled_seen  # within ``elapsed``: the last frame's steps
            compiled_seen += compiling
            due = self.clock.advance(min(elapsed, MAX_FRAME_TIME))
            last = now
            todo, ran, started = min(due, self._limit(steps)), 0, self._wall()
            for _ in range(todo):
                if activity.finished():
                    break
                if ran and self._wall() - started >= MAX_FRAME_TIME:
                    break  # steps slower than real time: catching up would only make the next frame later
                activity.step()
                steps += 1
                ran += 1
                self._after_step(activity, steps)
            if not self.clock.paused:
                skipped = 0 if activity.finished() else (todo - ran) * activity.dt
                lost = elapsed - min(elapsed, MAX_FRAME_TIME) + self.clock.dropped_time - dropped_before + skipped
                # Kernels compiled in those steps (a first start) are a one-off wait, not a game too slow
                # for real time: left out of the keeper's verdict, and named on screen instead.
                self.keeper.frame(elapsed - compiling, max(0.0, lost - compiling))
            in_steps = jit.compile_seconds() - compiled_seen  # this frame's steps (the keeper counts it next frame)
            if in_steps >= _COMPILE_NOTE:  # shown while the next steps may compile more
                self._compiling_note(compiled_seen + in_steps - compiled_at_start)
            elif ran and self._note is not None and self._note[0] == _STARTING:
                self._note = None
            drawing = self._wall()
            if ran:
                self._step_cost = (drawing - started) / ran
            self.draw(activity)
            # The level is chosen on what it changes, the drawing; the steps count only as many as
            # a frame at the budget's rate runs (see engine.render.quality), none while paused.
            fixed = 0.0 if self.clock.paused else self._step_cost * self.quality.budget / activity.dt
            if self.quality.frame(self._wall() - drawing, fixed):
                self._apply_quality()
                self.keeper.restart()  # the verdict is on the level the governor chose, not the one it left
            meter.tick(now)
            self.fps = meter.rate
        return steps

    def _compiling_note(self, seconds: float) -> None:
        """Say on screen, and once on stderr, that the steps compile kernels (a first start after an install)."""
        self._note = (f"compiling the engine's kernels: {seconds:.0f} s so far ({_ONCE})", self._wall() + _NOTE_SECONDS)
        if not self._compile_told:
            self._compile_told = True
            print(
                f"puppetphone: compiling the engine's kernels ({_ONCE}: they are cached for the next starts)",
                file=sys.stderr,
            )

    def draw(self, activity: Activity, complete: bool = False) -> None:
        """Draw the activity's current state into the target (and show it in a window).

        ``complete`` (always so headless): a frame that waits for background work rather than show it unfinished.
        """
        self.open()
        scene = RenderScene(complete=complete or self.options.headless)
        alpha = self.clock.alpha if self.clock is not None else 0.0
        activity.draw(scene, alpha, self.viewer.size)
        self._draw_notes(scene)
        self.viewer.camera = activity.camera
        self.viewer.draw(scene)
        if self.options.hud_dump is not None:
            self._dump_hud(scene)

    def _dump_hud(self, scene: RenderScene) -> None:
        """The overlay's lines and the step they show, to ``hud_dump`` (temp file + rename; at most 10 a second)."""
        now = self._wall()
        if now - self._hud_at < HUD_DUMP_INTERVAL:
            return
        self._hud_at = now
        path = self.options.hud_dump
        assert path is not None
        tmp = path.with_name(path.name + ".tmp")
        try:
            tmp.write_text("\n".join(t.text for t in scene.texts) + "\n", encoding="utf-8")
            os.replace(tmp, path)
        except OSError as exc:  # a HUD file is a convenience: the session goes on without it
            print(f"hud dump: {exc}", file=sys.stderr)
            self.options.hud_dump = None

    def _draw_notes(self, scene: RenderScene) -> None:
        """The runner's own words on screen: a quality change, and that the game is behind real time."""
        if self._note is not None and self._wall() < self._note[1]:
            scene.add_text(self._note[0], size=22, anchor=(0.5, 0.12))
        behind = self.keeper.behind()
        if behind is not None:
            scene.add_text(behind, size=20, color=(1.0, 0.8, 0.45), anchor=(0.5, 0.94))

    def _take_screenshot(self, activity: Activity) -> None:
        from engine.render.target import save_image

        if self.viewer is not None:
            self.viewer.keep_next_frame()  # a window may otherwise draw the frame where it cannot be read
        self.draw(activity, complete=True)
        assert self.options.screenshot is not None
        self._shot = save_image(self.viewer.read_pixels(), self.options.screenshot)

    def close(self) -> None:
        """Release the window or off-screen target."""
        if self.viewer is not None:
            self.viewer.close()
            self.viewer = None
