// PuppetPhone view worker: the page's WebSocket and the magic window, on one thread that does nothing else.
//
// Why one thread: a frame is stamped the moment it arrives, decoded, acknowledged to the engine at once
// (the engine's back-pressure sees the network and this thread), and drawn at this thread's next animation
// frame into the page's canvas (an OffscreenCanvas the main thread transferred here). No hand-off between
// threads: with a socket worker and a separate render worker, every frame waited for the render thread to
// come back to its message queue (and on a loaded two-core machine, for a third thread to be scheduled),
// 136 ms at the median from publication to availability in one measurement, against 23 ms to decoding.
// Sensor events and the page's layout on the main thread never delay a frame.
//
// Where this thread cannot draw (no OffscreenCanvas, no WebGL2 in a worker) and in AR (the XR session lives
// on the main thread), frames go to the main thread instead: at most IN_FLIGHT wait there, and a newer one
// replaces the one held back, so a busy main thread gets the newest frame, never a growing queue.
//
// From the main thread: {connect: url}, {send: text} (a reading, a ping), {canvas, size} (draw here),
// {size: [w, h]} (device pixels), {pause: bool} (true: frames go to the main thread), {got: step} (the main
// thread took a frame), {resolution: r | null} (hold the drawing resolution at r; null: adapt), {report}.
// To it: {open}, {close}, {text} (the engine's JSON), {frame}, {error}, {status}, {report}, {cannotDraw}.
"use strict";
importScripts("stream.js", "render.js");

const IN_FLIGHT = 2;
const clock = () => performance.timeOrigin + performance.now();
let ws = null, decoder = null, inFlight = 0, held = null;
let renderer = null, size = [1, 1], paused = true, lastStatus = 0, fresh = false;
// Forwarding to the main thread: whether it needs the scene again, the tracks it has, the cells changed since.
let resend = true, sentMarks = null, forwardDirty = null;
const stream = new SceneStream(), counter = new FrameCounter();

// This thread draws when it has a renderer and is not paused; else frames go to the main thread.
const drawsHere = () => renderer !== null && !paused;

function took() { inFlight = Math.max(0, inFlight - 1); flush(); }

function flush() {
  if (!held || inFlight >= IN_FLIGHT) return;
  const frame = held;
  held = null;
  inFlight += 1;
  if (resend) { frame.extras = decoder.extras; resend = false; sentMarks = null; }
  // The tracks go only when they changed since the last frame the main thread got (a whole grid when new).
  if (frame.marks === sentMarks && !forwardDirty) frame.marks = undefined;
  else {
    frame.marksDirty = frame.marks === sentMarks ? forwardDirty : (frame.marks ? [0, 0, frame.marks.nz, frame.marks.nx] : null);
    sentMarks = frame.marks;
  }
  forwardDirty = null;
  postMessage({ frame });  // copied, not transferred: the decoder keeps the rows of kinds that do not change
}

function open(url) {
  decoder = new StreamDecoder(); inFlight = 0; held = null; resend = true; sentMarks = null; forwardDirty = null;
  stream.reset();
  const sock = new WebSocket(url);
  sock.binaryType = "arraybuffer";
  ws = sock;
  sock.onopen = () => postMessage({ open: true });
  sock.onclose = () => { if (ws === sock) ws = null; postMessage({ close: true }); };
  sock.onmessage = (ev) => {
    const arrived = clock();
    if (typeof ev.data === "string") { postMessage({ text: ev.data }); return; }
    let frame;
    try { frame = decoder.receive(ev.data); } catch (err) { postMessage({ error: err.message }); return; }
    sock.send(JSON.stringify({ ack: frame.step }));
    frame.arrived = arrived; frame.decoded = clock();
    stream.accept(frame, performance.now());  // drawn at this thread's next animation frame
    fresh = true;
    if (drawsHere()) return;
    if (frame.extras) resend = true;
    forwardDirty = unionRect(forwardDirty, frame.marksDirty);
    held = frame;
    flush();
  };
}

function draw() {
  requestAnimationFrame(draw);
  if (!drawsHere() || !stream.extras) return;
  const w = Math.max(1, Math.round(size[0] * counter.resolution)), h = Math.max(1, Math.round(size[1] * counter.resolution));
  if (renderer.canvas.width !== w || renderer.canvas.height !== h) { renderer.canvas.width = w; renderer.canvas.height = h; }
  // performance.now(), not rAF's time: that is the frame's start, maybe before the message came.
  const frame = stream.sample(performance.now());
  if (!frame) return;
  renderer.draw(frame, stream.extras);
  const t = performance.now();
  const renewed = counter.count(frame.step, t);
  if (renewed || (fresh && t - lastStatus > 100)) {
    lastStatus = t; fresh = false;
    postMessage({ status: { drawn: counter.drawn, step: counter.step, fps: counter.fps, resolution: counter.resolution,
      frames: stream.frames, bytes: stream.bytes } });
  }
}

onmessage = (e) => {
  const m = e.data;
  if (m.send !== undefined) { if (ws && ws.readyState === WebSocket.OPEN) ws.send(m.send); }
  else if (m.got !== undefined) took();
  else if (m.connect !== undefined) open(m.connect);
  if (m.size) size = m.size;
  if (m.resolution !== undefined) counter.hold(m.resolution);
  if (m.pause !== undefined && renderer) {
    paused = m.pause;
    inFlight = 0; held = null; resend = true;
  }
  if (m.report) postMessage({ report: { log: stream.log, drawLog: counter.drawLog, frames: stream.frames, bytes: stream.bytes } });
  if (m.canvas) {
    try {
      renderer = new PageRenderer(m.canvas);
      paused = false;
      requestAnimationFrame(draw);
    } catch (err) { postMessage({ cannotDraw: "the worker cannot draw (" + err.message + "): drawing on the main thread" }); }
  }
};
