// PuppetPhone render worker: the magic window drawn off the main thread, into the page's canvas
// (an OffscreenCanvas the main thread transferred here). Frames come decoded from the stream worker
// through a MessagePort, carrying only what changed; this thread keeps the newest two (stream.js) and
// draws at each of its animation frames, interpolated. Neither sensor events nor the page's layout on
// the main thread delay a frame, and the WebSocket is read on its own thread while this one draws.
//
// From the main thread: {canvas, size, port}, {size: [w, h]} (device pixels), {pause: bool} (AR draws
// on the main thread), {resolution: r | null} (hold the drawing at r of the device's pixels; null: adapt),
// {report: true}. To it: {status}, {report}, {cannotDraw: reason}.
"use strict";
importScripts("stream.js", "render.js");

let renderer = null, size = [1, 1], paused = false, lastStatus = 0;
const stream = new SceneStream(), counter = new FrameCounter();

function draw() {
  requestAnimationFrame(draw);
  if (paused || !stream.extras) return;
  const w = Math.max(1, Math.round(size[0] * counter.resolution)), h = Math.max(1, Math.round(size[1] * counter.resolution));
  if (renderer.canvas.width !== w || renderer.canvas.height !== h) { renderer.canvas.width = w; renderer.canvas.height = h; }
  // performance.now(), not rAF's time: that is the frame's start, maybe before the message came.
  const frame = stream.sample(performance.now());
  if (!frame) return;
  renderer.draw(frame, stream.extras);
  const t = performance.now();
  if (counter.count(frame.step, t) || t - lastStatus > 100) {
    lastStatus = t;
    postMessage({ status: { drawn: counter.drawn, step: counter.step, fps: counter.fps, resolution: counter.resolution,
      frames: stream.frames, bytes: stream.bytes } });
  }
}

onmessage = (e) => {
  const m = e.data;
  if (m.size) size = m.size;
  if (m.resolution !== undefined) counter.hold(m.resolution);
  if (m.pause !== undefined) { paused = m.pause; stream.reset(); }
  if (m.report) postMessage({ report: { log: stream.log, drawLog: counter.drawLog, frames: stream.frames, bytes: stream.bytes } });
  if (m.port) {
    m.port.onmessage = (ev) => {
      if (!ev.data.frame) return;
      stream.accept(ev.data.frame, performance.now());  // drawn at the next animation frame
      m.port.postMessage({ got: ev.data.frame.step });
    };
  }
  if (m.canvas) {
    try {
      renderer = new PageRenderer(m.canvas);
      requestAnimationFrame(draw);
    } catch (err) { postMessage({ cannotDraw: "the worker cannot draw (" + err.message + "): drawing on the main thread" }); }
  }
};
