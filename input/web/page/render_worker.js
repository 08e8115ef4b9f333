// PuppetPhone render worker: the magic window drawn off the main thread, into the page's canvas
// (an OffscreenCanvas the main thread transferred here). Frames come decoded from the stream worker
// through a MessagePort, carrying only what changed; this thread keeps the newest two (stream.js) and
// draws at its animation frames, only when there is something new to show: a frame not drawn yet, or a
// blend under way (frames more than a step apart). It never draws the same picture twice: a redrawing
// is CPU taken from the rasteriser, the stream worker and the engine, which share the cores.
// Neither sensor events nor the page's layout on the main thread delay a frame, and the WebSocket is
// read on its own thread while this one draws.
//
// Measured and not kept (bench phone-view and a worker timing its drawings, issue 33, session b33): the
// drawing's JavaScript takes about a millisecond, but its task then blocks while the software rasteriser
// finishes the picture and the canvas is read back for the compositor (65-80 ms at load 19). Drawing each
// frame as it arrived (not at the animation frame) drew the older of two frames queued meanwhile first;
// taking one frame at a time, asked for once the block was over, cost two thread wake-ups per frame and
// lost under load (pinned to one core: drawn p50 298 against 46 ms).
//
// From the main thread: {canvas, size, port}, {size: [w, h]} (device pixels), {pause: bool} (AR draws
// on the main thread), {resolution: r | null} (hold the drawing at r of the device's pixels; null: adapt),
// {report: true}. To it: {status}, {report}, {cannotDraw: reason}.
"use strict";
importScripts("stream.js", "render.js");

let renderer = null, size = [1, 1], paused = false, lastStatus = 0, resized = true, asked = false;
const stream = new SceneStream(), counter = new FrameCounter();

// At the next animation frame: draw if there is something new to show.
function later() {
  if (asked) return;
  asked = true;
  requestAnimationFrame(() => {
    asked = false;
    if (paused || !renderer || !stream.extras) return;
    const now = performance.now();  // not rAF's time: that is the frame's start, maybe before the message came
    if (!resized && !stream.wants(now)) return;
    draw(now);
    if (stream.wants(performance.now())) later();  // a blend under way: its next picture
  });
}

function draw(now) {
  const w = Math.max(1, Math.round(size[0] * counter.resolution)), h = Math.max(1, Math.round(size[1] * counter.resolution));
  if (renderer.canvas.width !== w || renderer.canvas.height !== h) { renderer.canvas.width = w; renderer.canvas.height = h; }
  resized = false;
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
  if (m.pause !== undefined) { paused = m.pause; stream.reset(); }
  if (m.report) {
    postMessage({ report: { log: stream.log, drawLog: counter.drawLog, shownLog: counter.shownLog, frames: stream.frames, bytes: stream.bytes } });
  }
  if (m.port) {
    m.port.onmessage = (ev) => {
      const f = ev.data.frame;
      if (!f) return;
      if (stream.fresh) f.behind = true;  // the frame before was never drawn: this thread is behind
      stream.accept(f, performance.now());
      m.port.postMessage({ got: f.step });
      later();
    };
  }
  if (m.canvas) {
    try {
      renderer = new PageRenderer(m.canvas);
    } catch (err) { postMessage({ cannotDraw: "the worker cannot draw (" + err.message + "): drawing on the main thread" }); }
  }
};
