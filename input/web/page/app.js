// PuppetPhone web controller: the phone's browser becomes the MotionStick, and the viewport.
// Streams one JSON reading per sensor event over a WebSocket (format: input/web/protocol.py) and draws
// the scene the engine streams back (stream_worker.js, render_worker.js, stream.js, render.js): the
// phone is the camera, the stick hangs from it. Modes: WebXR immersive-ar (the field placed on the floor by a hit test, the camera image
// behind it), else a "magic window" (device orientation turns the view over a plain sky).
// Plain scripts, no build step; served by the engine over HTTPS (sensors need a secure context).
"use strict";

const $ = (id) => document.getElementById(id);
const token = new URLSearchParams(location.search).get("t") || "";
const clock = () => performance.timeOrigin + performance.now();

const state = {
  open: false, seq: 0, touch: false, jump: false, cal: false, crouch: 0,
  o: [0, 0, 0], acc: null, rot: null, kind: "orientation", q: null, p: null,
  sensor: "none", lastSent: 0, taken: false, rtt: null, xrNote: "", placement: null,
};
// Threads: the stream worker (stream_worker.js) holds the WebSocket and decodes; the render worker
// (render_worker.js) draws the magic window into the page's canvas, transferred to it. This thread
// handles the sensors and the controls, and draws only in AR (the XR session is here) or where a
// worker cannot draw: then the stream worker sends its frames here.
const worker = new Worker("stream_worker.js");
worker.onerror = (e) => { $("status").textContent = "stream: " + e.message; };
const stream = new SceneStream(), counter = new FrameCounter();
let renderer = null, drawsHere = false, painter = null;
// What the bench and the tests read: frames drawn, the step on screen, frames per second, who draws;
// report() gives the logs (per step: published, reached the stream worker, decoded, available to the
// drawer; when each step was first drawn, and first drawn as itself rather than a blend towards it), all in
// ms since the epoch; camera: the rotation of the view last drawn (x y z w).
const reportWaiters = [];
// holdResolution(r) keeps the drawing at r of the device's pixels (null: adapt to the frame rate again).
window.ppView = { drawn: 0, step: -1, fps: 0, resolution: 1, frames: 0, bytes: 0, camera: null, where: "render worker",
  report: () => (drawsHere || state.kind === "xr"
    ? Promise.resolve({ log: stream.log, drawLog: counter.drawLog, shownLog: counter.shownLog, frames: stream.frames, bytes: stream.bytes })
    : new Promise((resolve) => { reportWaiters.push(resolve); painter.postMessage({ report: true }); })),
  holdResolution: (r) => { counter.hold(r); if (painter) painter.postMessage({ resolution: r }); } };

function canvasSize() {
  const canvas = $("view"), px = Math.min(devicePixelRatio, 2);
  return [Math.max(1, Math.round(canvas.clientWidth * px)), Math.max(1, Math.round(canvas.clientHeight * px))];
}

// Draw on this thread from now on (on a fresh canvas if the old one went to the render worker).
function drawHere(reason) {
  let canvas = $("view");
  if (canvas.dataset.transferred) {
    const fresh = document.createElement("canvas");
    fresh.id = "view";
    canvas.replaceWith(fresh);
    canvas = fresh;
  }
  drawsHere = true; window.ppView.where = "main thread";
  worker.postMessage({ drawer: null });
  try { renderer = new PageRenderer(canvas, { xrCompatible: true }); } catch (err) { $("fps").textContent = "view: " + err.message; }
  if (reason) $("status").textContent = "view: " + reason;
}

function onPainter(e) {
  const m = e.data;
  if (m.status) { Object.assign(window.ppView, m.status); showFps(m.status); }
  else if (m.report) reportWaiters.splice(0).forEach((resolve) => resolve(m.report));
  else if (m.cannotDraw !== undefined) drawHere(m.cannotDraw);
}

{
  const canvas = $("view");
  if (typeof canvas.transferControlToOffscreen === "function") {
    const off = canvas.transferControlToOffscreen(), link = new MessageChannel();
    canvas.dataset.transferred = "1";
    painter = new Worker("render_worker.js");
    painter.onmessage = onPainter;
    painter.onerror = (e) => { $("status").textContent = "view: " + e.message; };
    painter.postMessage({ canvas: off, size: canvasSize(), port: link.port2 }, [off, link.port2]);
    worker.postMessage({ drawer: link.port1 }, [link.port1]);
    window.addEventListener("resize", () => painter.postMessage({ size: canvasSize() }));
  } else {
    drawHere("");
  }
}

function setState(text, cls) { const el = $("state"); el.textContent = text; el.className = "state " + cls; }
function setMode() {
  const names = { xr: state.placement ? "AR: field on your floor (WebXR immersive-ar, 6-DoF)" : "AR: finding the floor… (WebXR immersive-ar)",
    orientation: "magic window: orientation 3-DoF", none: "magic window: no motion sensor, touch only" };
  $("mode").textContent = "mode: " + names[state.sensor] + (state.xrNote ? " · " + state.xrNote : "");
}

function send(reading) {
  if (!state.open) return;
  worker.postMessage({ send: JSON.stringify(reading) });
  state.lastSent = performance.now();
}

// One reading: the current sensor values, the buttons; one-shot flags are cleared once sent.
function sendReading(t) {
  const r = { seq: state.seq++, t: t === undefined ? clock() : t, kind: state.kind,
    touch: state.touch, jump: state.jump, cal: state.cal, crouch: state.crouch };
  if (state.kind === "xr") {
    // Once the field stands on the floor, the pose is sent in the field's coordinates (the engine's world).
    const pose = state.placement ? localToField(state.placement, state.q, state.p) : { q: state.q, p: state.p };
    r.q = pose.q; r.p = pose.p;
  } else { r.o = state.o; }
  if (state.acc) r.acc = state.acc;
  if (state.rot) r.rot = state.rot;
  send(r);
  state.jump = false;
  state.cal = false;
}

// The WebSocket lives in the stream worker (stream_worker.js): readings and pings go out through it,
// the engine's JSON comes back here, and scene frames come here only when this thread draws.
worker.onmessage = (e) => {
  const m = e.data;
  if (m.frame) {
    if (stream.fresh) m.frame.behind = true;  // the frame before was never drawn: this thread is behind
    stream.accept(m.frame, performance.now());
    worker.postMessage({ got: m.frame.step });
  } else if (m.text !== undefined) {
    onText(m.text);
  } else if (m.open) {
    state.open = true;
    setState("connected", "on");
  } else if (m.close) {
    state.open = false;
    stream.reset();  // a new connection starts from a new scene GLB
    if (state.taken) return;
    setState("disconnected: retrying", "off");
    setTimeout(connect, 1000);
  } else if (m.error !== undefined) {
    $("status").textContent = "view: " + m.error;
  }
};

function onText(text) {
  let msg;
  try { msg = JSON.parse(text); } catch (e) { return; }
  if (msg.pong !== undefined) {
    state.rtt = clock() - msg.pong;
    $("latency").textContent = "latency: " + (state.rtt / 2).toFixed(1) + " ms (round trip " + state.rtt.toFixed(1) + ")";
  } else if (msg.hello) {
    setState("connected: " + msg.hello + " drives the puppet", "on");
  } else if (msg.taken) {
    state.taken = true;
    $("start").hidden = true;
    $("taken").hidden = false;
    setState("every puppet is taken", "off");
  }
}

function connect() {
  setState("connecting…", "wait");
  worker.postMessage({ connect: (location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws?t=" + encodeURIComponent(token) });
}

let sensorShown = -Infinity;
function onOrientation(e) {
  if (state.kind === "xr") return;
  if (e.alpha === null && e.beta === null && e.gamma === null) return;
  state.o = [e.alpha || 0, e.beta || 0, e.gamma || 0];
  if (state.sensor === "none") { state.sensor = "orientation"; setMode(); }
  sendReading();
  // The angles on the page four times a second, not at every event: each change of text lays out and
  // repaints the page on this thread, which also carries the readings.
  const now = performance.now();
  if (now - sensorShown > 250) {
    sensorShown = now;
    $("status").textContent = "sensor: α " + state.o[0].toFixed(0) + "° β " + state.o[1].toFixed(0) + "° γ " + state.o[2].toFixed(0) + "°";
  }
}

function onMotion(e) {
  const a = e.acceleration && e.acceleration.x !== null ? e.acceleration : e.accelerationIncludingGravity;
  if (a && a.x !== null) state.acc = [a.x, a.y, a.z];
  const r = e.rotationRate;
  if (r && r.alpha !== null) state.rot = [r.alpha, r.beta, r.gamma];
  // Readings go out on orientation events (motion values ride along); a phone without an
  // orientation sensor still streams its acceleration at the motion sensor's rate.
  if (state.sensor === "none" && state.acc) sendReading();
}

async function enableSensors() {
  // iOS asks for permission, and only from a user gesture: this click.
  try {
    if (typeof DeviceOrientationEvent !== "undefined" && typeof DeviceOrientationEvent.requestPermission === "function") {
      const answer = await DeviceOrientationEvent.requestPermission();
      if (answer !== "granted") { $("status").textContent = "sensor: permission refused (touch only)"; }
    }
    if (typeof DeviceMotionEvent !== "undefined" && typeof DeviceMotionEvent.requestPermission === "function") {
      await DeviceMotionEvent.requestPermission();
    }
  } catch (err) {
    $("status").textContent = "sensor: " + err;
  }
  window.addEventListener("deviceorientation", onOrientation);
  window.addEventListener("devicemotion", onMotion);
  $("start").hidden = true;
  $("calib").hidden = false;  // "this is the screen": asked for, never guessed from the first tap
}

function confirmCalibration() {
  state.cal = true;
  sendReading();
  $("calib").hidden = true;
  $("calibrated").hidden = false;
  setTimeout(() => { $("calibrated").hidden = true; }, 1500);
}

// The magic window on this thread (where the worker cannot draw): the newest frames, interpolated.
function drawFrame() {
  if (state.kind !== "xr") requestAnimationFrame(drawFrame);
  if (!drawsHere || !renderer || !stream.extras) return;
  const canvas = $("view"), [cw, ch] = canvasSize();
  const w = Math.max(1, Math.round(cw * counter.resolution)), h = Math.max(1, Math.round(ch * counter.resolution));
  const resized = canvas.width !== w || canvas.height !== h;
  if (resized) { canvas.width = w; canvas.height = h; }
  if (!resized && !stream.wants(performance.now())) return;  // the same picture again: not drawn (render_worker.js)
  const frame = stream.sample(performance.now());
  if (!frame) return;
  renderer.draw(frame, stream.extras);
  countFrame(frame, performance.now());  // not rAF's time: that is the frame's start, before the message came
}

function countFrame(frame, now) {
  const renewed = counter.count(frame.step, now, frame.time), view = window.ppView, q = frame.camera.q;
  Object.assign(view, { drawn: counter.drawn, step: counter.step, fps: counter.fps, resolution: counter.resolution,
    frames: stream.frames, bytes: stream.bytes, camera: [q[0], q[1], q[2], q[3]] });
  if (renewed) showFps(view);
}

let fpsShown = 0;
function showFps(v) {
  if (performance.now() - fpsShown < 1000) return;
  fpsShown = performance.now();
  $("fps").textContent = "view: " + v.fps.toFixed(0) + " fps, step " + v.step + (v.resolution < 1 ? ", " + Math.round(100 * v.resolution) + " % resolution" : "")
    + " (" + window.ppView.where + ")";
}

async function startXR() {
  const session = await navigator.xr.requestSession("immersive-ar", { requiredFeatures: ["local"],
    optionalFeatures: ["hit-test", "dom-overlay"], domOverlay: { root: document.body } });
  // The XR session draws on this thread: the worker forwards its frames here meanwhile.
  if (!renderer) renderer = new PageRenderer(document.createElement("canvas"), { xrCompatible: true });
  if (painter && !drawsHere) { painter.postMessage({ pause: true }); worker.postMessage({ drawer: null }); }
  const gl = renderer.gl;
  await gl.makeXRCompatible();
  session.updateRenderState({ baseLayer: new XRWebGLLayer(session, gl) });
  const space = await session.requestReferenceSpace("local");
  const viewer = await session.requestReferenceSpace("viewer");
  const hits = session.requestHitTestSource ? await session.requestHitTestSource({ space: viewer }).catch(() => null) : null;
  state.kind = "xr"; state.sensor = "xr"; state.placement = null; state.xrNote = hits ? "" : "no hit test: field at your feet";
  document.body.classList.add("ar");
  setMode();
  $("start").hidden = true;
  const frame = (time, xrFrame) => {
    session.requestAnimationFrame(frame);
    const pose = xrFrame.getViewerPose(space);
    if (!pose) return;
    const t = pose.transform, o = t.orientation, p = t.position;
    state.q = [o.x, o.y, o.z, o.w]; state.p = [p.x, p.y, p.z];
    if (!state.placement) {
      const found = hits ? xrFrame.getHitTestResults(hits) : [];
      const floor = found.length ? found[0].getPose(space).transform.position : (hits ? null : { x: p.x, y: p.y - 1.4, z: p.z - 1.5 });
      if (floor) { state.placement = placeField([floor.x, floor.y, floor.z], state.p); setMode(); }
    }
    sendReading();
    const look = stream.extras, shown = stream.sample(time);
    if (!state.placement || !look || !shown) return;
    const layer = session.renderState.baseLayer, toLocal = fieldToLocalMatrix(state.placement);
    gl.bindFramebuffer(gl.FRAMEBUFFER, layer.framebuffer);
    const eye = localToField(state.placement, state.q, state.p).p;
    pose.views.forEach((view, i) => {
      const vp = layer.getViewport(view);
      renderer.draw(shown, look, { proj: view.projectionMatrix, view: mul4(view.transform.inverse.matrix, toLocal), eye,
        viewport: [vp.x, vp.y, vp.width, vp.height], first: i === 0 });
    });
    countFrame(shown, time);
  };
  session.addEventListener("end", () => {
    state.kind = "orientation"; state.sensor = "orientation"; state.placement = null; document.body.classList.remove("ar");
    if (painter && !drawsHere) { const link = new MessageChannel(); painter.postMessage({ pause: false, port: link.port2 }, [link.port2]); worker.postMessage({ drawer: link.port1 }, [link.port1]); }
    setMode(); requestAnimationFrame(drawFrame);
  });
  session.requestAnimationFrame(frame);
}

// Asked for AR and refused (no WebXR, no immersive-ar, no permission): the magic window, and say why.
function fallBackFromXR(err) {
  state.xrNote = "AR refused (" + (err && err.name ? err.name : err) + "): magic window instead";
  setMode();
  enableSensors();
}

function press(el, down, up) {
  el.addEventListener("pointerdown", (e) => { e.preventDefault(); el.setPointerCapture(e.pointerId); down(); });
  el.addEventListener("pointerup", (e) => { e.preventDefault(); up(); });
  el.addEventListener("pointercancel", () => up());
}

press($("touch"), () => { state.touch = true; $("touch").classList.add("down"); sendReading(); },
  () => { if (!state.touch) return; state.touch = false; $("touch").classList.remove("down"); sendReading(); });
press($("jump"), () => { state.jump = true; $("jump").classList.add("down"); sendReading(); },
  () => $("jump").classList.remove("down"));
// The slider's value is approached at CROUCH_SPEED per second: the crouch lowers the stick, and a
// slider pushed back up at once would lift it faster than a flick, which means "jump".
const CROUCH_SPEED = 1.5;
let crouchTarget = 0;
$("crouch").addEventListener("input", (e) => { crouchTarget = Number(e.target.value); });
setInterval(() => {
  if (state.crouch === crouchTarget) return;
  const step = CROUCH_SPEED / 60;
  state.crouch = Math.abs(crouchTarget - state.crouch) <= step ? crouchTarget
    : state.crouch + Math.sign(crouchTarget - state.crouch) * step;
  sendReading();
}, 1000 / 60);
$("calibrate").addEventListener("click", () => {
  if (state.kind === "xr") { state.placement = null; setMode(); return; }  // in AR: place the field again
  $("calib").hidden = false;
});
$("calib-ok").addEventListener("click", confirmCalibration);
$("enable").addEventListener("click", enableSensors);
$("xr").addEventListener("click", () => startXR().catch(fallBackFromXR));

if (navigator.xr && navigator.xr.isSessionSupported) {
  navigator.xr.isSessionSupported("immersive-ar").then((ok) => { $("xr").hidden = !ok; }).catch(() => {});
}
// Without sensor events (a desktop browser, a paused sensor) the controller still says it is there.
setInterval(() => { if (performance.now() - state.lastSent > 250) sendReading(); }, 250);
setInterval(() => send({ ping: clock() }), 1000);
setMode();
connect();
requestAnimationFrame(drawFrame);
