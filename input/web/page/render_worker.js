// PuppetPhone render worker: the magic window drawn off the main thread, into the page's canvas
// (an OffscreenCanvas the main thread transferred here). Frames come decoded from the stream worker
// through a MessagePort, carrying only what changed; this thread keeps the newest two (stream.js).
// Neither sensor events nor the page's layout on the main thread delay a frame, and the WebSocket is
// read on its own thread while this one draws.
//
// When it draws: as soon as a frame arrives, not at the next animation frame (waiting for it added up to a
// display interval to every frame's latency: bench phone-view, issue 33), but never sooner than MIN_GAP
// after the last drawing (a phone shows 60 Hz; a drawing more is CPU taken from the stream and the
// engine), and never the same picture twice (no new frame, no blend under way: nothing is drawn). Between
// frames further apart than a step (a slow phone gets fewer), animation frames draw the blend.
//
// When it takes the next frame: only once its drawing is done. The drawing's JavaScript takes about a
// millisecond, but the task then blocks while the software rasteriser finishes the picture and the canvas
// is read back for the compositor (measured: 65-80 ms a drawing at load 19, against 0.5 ms of
// JavaScript). A frame posted meanwhile waited in this thread's queue, and the older of two queued frames
// was drawn first. So this thread tells the stream worker {got} from a task after the drawing's (the
// block is over by then), and the stream worker keeps only the newest frame until then: whatever arrived
// during a drawing replaces what it holds, and the next drawing starts with the newest.
//
// From the main thread: {canvas, size, port}, {size: [w, h]} (device pixels), {pause: bool} (AR draws
// on the main thread), {resolution: r | null} (hold the drawing at r of the device's pixels; null: adapt),
// {report: true}. To it: {status}, {report}, {cannotDraw: reason}.
"use strict";
importScripts("stream.js", "render.js");

const MIN_GAP = 1000 / 60 - 2;  // ms: a 60 Hz display's interval, less a margin for the arrival's jitter
let renderer = null, size = [1, 1], paused = false, lastStatus = 0, lastDraw = -Infinity, resized = true, asked = false;
let port = null, waiting = false;  // the stream worker's port; a frame taken, {got} not sent yet
const stream = new SceneStream(), counter = new FrameCounter();

// Draw now if there is something new to show and the last drawing is MIN_GAP old (true: drawn); else at
// the next animation frame if there is something new.
function drawIfDue() {
  if (paused || !renderer || !stream.extras) return false;
  const now = performance.now();
  if (!resized && !stream.wants(now)) return false;
  if (now - lastDraw < MIN_GAP) { later(); return false; }
  lastDraw = now;
  draw(now);
  if (stream.wants(performance.now())) later();  // a blend under way: its next picture
  if (waiting) setTimeout(ready, 0);  // runs once the drawing's commit is over
  return true;
}

// Ready for the next frame (see above); a frame taken but not drawn yet keeps it waiting until drawn.
function ready() {
  if (!waiting || (!paused && renderer && stream.extras && stream.fresh)) return;
  waiting = false;
  port.postMessage({ got: true });
}

function later() {
  if (asked) return;
  asked = true;
  requestAnimationFrame(() => { asked = false; drawIfDue(); });
}

function draw(now) {
  const w = Math.max(1, Math.round(size[0] * counter.resolution)), h = Math.max(1, Math.round(size[1] * counter.resolution));
  if (renderer.canvas.width !== w || renderer.canvas.height !== h) { renderer.canvas.width = w; renderer.canvas.height = h; }
  resized = false;
  // performance.now(), not rAF's time: that is the frame's start, maybe before the message came.
  const frame = stream.sample(now);
  if (!frame) return;
  renderer.draw(frame, stream.extras);
  const t = performance.now();
  if (counter.count(frame.step, t, frame.time) || t - lastStatus > 100) {
    lastStatus = t;
    const q = frame.camera.q;
    postMessage({ status: { drawn: counter.drawn, step: counter.step, fps: counter.fps, resolution: counter.resolution,
      frames: stream.frames, bytes: stream.bytes, camera: [q[0], q[1], q[2], q[3]] } });
  }
}

onmessage = (e) => {
  const m = e.data;
  if (m.size) { size = m.size; resized = true; later(); }
  if (m.resolution !== undefined) { counter.hold(m.resolution); resized = true; later(); }
  if (m.pause !== undefined) { paused = m.pause; stream.reset(); ready(); }
  if (m.report) {
    postMessage({ report: { log: stream.log, drawLog: counter.drawLog, shownLog: counter.shownLog, frames: stream.frames, bytes: stream.bytes } });
  }
  if (m.port) {
    port = m.port; waiting = false;
    port.onmessage = (ev) => {
      if (!ev.data.frame) return;
      stream.accept(ev.data.frame, performance.now());
      waiting = true;
      if (!drawIfDue()) ready();  // not drawn now: taken at once if it will not be drawn later either
    };
  }
  if (m.canvas) {
    try {
      renderer = new PageRenderer(m.canvas);
    } catch (err) { postMessage({ cannotDraw: "the worker cannot draw (" + err.message + "): drawing on the main thread" }); }
  }
};
