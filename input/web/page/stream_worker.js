// PuppetPhone stream worker: the page's WebSocket, on a thread that does nothing else.
//
// Why its own thread: a frame is stamped the moment it arrives, decoded, acknowledged to the engine at once
// (the engine's back-pressure sees the network and this thread, not the drawing), and the phone's readings
// go out at once. Tried: one worker that also drew (no hand-off). Under load its socket waited for each
// drawing: the acknowledgements came late, so the engine sent a frame every third or fourth step instead of
// every step, and the readings that turn the view waited behind the drawing too (bench phone-view and the
// page-view test, reported with issue 33). So frames go on, as messages that carry only what changed
// (stream.js Forwarder), to whoever draws: the render worker (render_worker.js, through a MessagePort) or,
// in AR and where a worker cannot draw, the main thread. At most IN_FLIGHT frames wait there for the
// drawer; a newer one replaces the one held back, so a busy drawer gets the newest frame, never a queue
// (one in flight, released once the drawer's drawing was over, was tried: render_worker.js).
//
// From the main thread: {connect: url}, {send: text} (a reading, a ping), {drawer: port | null} (where
// frames go; null: the main thread), {got: step} (the main thread took a frame). To it: {open}, {close},
// {text} (the engine's JSON), {frame}, {error}. From the drawer's port: {got: step}.
"use strict";
importScripts("stream.js");

const IN_FLIGHT = 2;
let ws = null, decoder = null, inFlight = 0, held = null, drawer = null;
const forward = new Forwarder();
const clock = () => performance.timeOrigin + performance.now();

function took() { inFlight = Math.max(0, inFlight - 1); flush(); }

function flush() {
  if (!held || inFlight >= IN_FLIGHT) return;
  const frame = forward.message(held, decoder.extras);
  held = null;
  inFlight += 1;
  // Copied, not transferred: the decoder keeps the arrays of the kinds that do not change.
  if (drawer) drawer.postMessage({ frame }); else postMessage({ frame });
}

function open(url) {
  decoder = new StreamDecoder(); inFlight = 0; held = null; forward.reset();
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
    forward.note(frame);
    // A frame that replaces one held back: the drawer is behind, and shows it as it is (no blend: stream.js).
    if (held) frame.behind = true;
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
    inFlight = 0; held = null; forward.reset();  // a new drawer holds nothing: the next frame carries all
  }
};
