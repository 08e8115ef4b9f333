// PuppetPhone stream worker: the page's WebSocket, on a thread that does nothing else.
//
// Why: on the main thread a scene frame waited behind everything else there (software WebGL, layout,
// sensor events) before it was even read: 68-76 ms from the engine's step to the page at p99. Here a
// frame is stamped the moment it arrives, decoded, acknowledged to the engine at once (the engine's
// back-pressure sees the network and this thread), and passed on as float rows in transferred buffers
// to whoever draws: the render worker (render_worker.js, through a MessagePort) or, in AR and where
// a worker cannot draw, the main thread. At most IN_FLIGHT frames wait there for the drawer; a newer
// one replaces the one held back, so a busy drawer gets the newest frame, never a growing queue.
//
// From the main thread: {connect: url}, {send: text} (a reading, a ping), {drawer: port | null} (where
// frames go; null: the main thread), {got: step} (the main thread took a frame). To it: {open}, {close},
// {text} (the engine's JSON), {frame}, {error}. From the drawer's port: {got: step}.
"use strict";
importScripts("stream.js");

const IN_FLIGHT = 2;
const NOT_SENT = {};
let ws = null, decoder = null, inFlight = 0, held = null, drawer = null, resend = false, sentMarks = NOT_SENT;
const clock = () => performance.timeOrigin + performance.now();

function took() { inFlight = Math.max(0, inFlight - 1); flush(); }

function flush() {
  if (!held || inFlight >= IN_FLIGHT) return;
  const frame = held;
  held = null;
  inFlight += 1;
  // The tracks' grid goes only when it changed since the last frame the drawer got, softened (a copy).
  if (frame.marks === sentMarks) frame.marks = undefined; else { sentMarks = frame.marks; frame.marks = softenMarks(frame.marks); }
  const buffers = Object.values(frame.rows).map((a) => a.buffer);
  if (drawer) drawer.postMessage({ frame }, buffers); else postMessage({ frame }, buffers);
}

function open(url) {
  decoder = new StreamDecoder(); inFlight = 0; held = null; sentMarks = NOT_SENT;
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
    // A frame held back is replaced: keep the scene it carried, and give a new drawer the scene.
    if ((held && held.extras) || resend) frame.extras = frame.extras || decoder.extras;
    resend = false;
    held = frame;
    flush();
  };
}

onmessage = (e) => {
  const m = e.data;
  if (m.send !== undefined) { if (ws && ws.readyState === WebSocket.OPEN) ws.send(m.send); }
  else if (m.got !== undefined) took();
  else if (m.connect !== undefined) open(m.connect);
  else if (m.drawer !== undefined) {
    drawer = m.drawer;
    if (drawer) drawer.onmessage = (ev) => { if (ev.data.got !== undefined) took(); };
    inFlight = 0; held = null; resend = true; sentMarks = NOT_SENT;
  }
};
