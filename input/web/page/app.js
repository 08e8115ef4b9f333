// PuppetPhone web controller: the phone's browser becomes the MotionStick, and the viewport.
// Streams one JSON reading per sensor event over a WebSocket (format: input/web/protocol.py) and draws
// the scene the engine streams back (stream.js, render.js): the phone is the camera, the stick hangs
// from it. Modes: WebXR immersive-ar (the field placed on the floor by a hit test, the camera image
// behind it), else a "magic window" (device orientation turns the view over a plain sky).
// Plain scripts, no build step; served by the engine over HTTPS (sensors need a secure context).
"use strict";

const $ = (id) => document.getElementById(id);
const token = new URLSearchParams(location.search).get("t") || "";
const clock = () => performance.timeOrigin + performance.now();

const state = {
  ws: null, seq: 0, touch: false, jump: false, cal: false, crouch: 0,
  o: [0, 0, 0], acc: null, rot: null, kind: "orientation", q: null, p: null,
  sensor: "none", lastSent: 0, taken: false, rtt: null, xrNote: "", placement: null,
};
const stream = new SceneStream();
let renderer = null;
try { renderer = new PageRenderer($("view"), { xrCompatible: true }); } catch (err) { $("fps").textContent = "view: " + err.message; }
// What the bench and the tests read: frames drawn, the step on screen, frames per second.
window.ppView = { drawn: 0, step: -1, fps: 0, stream, drawLog: [] };

function setState(text, cls) { const el = $("state"); el.textContent = text; el.className = "state " + cls; }
function setMode() {
  const names = { xr: state.placement ? "AR: field on your floor (WebXR immersive-ar, 6-DoF)" : "AR: finding the floor… (WebXR immersive-ar)",
    orientation: "magic window: orientation 3-DoF", none: "magic window: no motion sensor, touch only" };
  $("mode").textContent = "mode: " + names[state.sensor] + (state.xrNote ? " · " + state.xrNote : "");
}

function send(reading) {
  const ws = state.ws;
  if (!ws || ws.readyState !== WebSocket.OPEN) return;
  ws.send(JSON.stringify(reading));
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

function connect() {
  const url = (location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws?t=" + encodeURIComponent(token);
  setState("connecting…", "wait");
  const ws = new WebSocket(url);
  ws.binaryType = "arraybuffer";
  state.ws = ws;
  ws.onopen = () => setState("connected", "on");
  ws.onmessage = (ev) => {
    if (ev.data instanceof ArrayBuffer) {
      try { send({ ack: stream.receive(ev.data, performance.now()) }); } catch (err) { $("status").textContent = "view: " + err.message; }
      return;
    }
    let msg;
    try { msg = JSON.parse(ev.data); } catch (e) { return; }
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
  };
  ws.onclose = () => {
    state.ws = null;
    stream.state = null;  // a new connection starts from a new scene GLB
    if (state.taken) return;
    setState("disconnected: retrying", "off");
    setTimeout(connect, 1000);
  };
}

function onOrientation(e) {
  if (state.kind === "xr") return;
  if (e.alpha === null && e.beta === null && e.gamma === null) return;
  state.o = [e.alpha || 0, e.beta || 0, e.gamma || 0];
  if (state.sensor === "none") { state.sensor = "orientation"; setMode(); }
  $("status").textContent = "sensor: α " + state.o[0].toFixed(0) + "° β " + state.o[1].toFixed(0) + "° γ " + state.o[2].toFixed(0) + "°";
  sendReading();
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

// The magic window: draw the newest frames, interpolated, at the display's rate. A phone (or a
// software renderer) that cannot keep 30 fps draws fewer pixels, stretched, rather than fewer frames.
let fpsCount = 0, fpsStart = performance.now(), resolution = 1;
const MIN_RESOLUTION = 0.5;
function drawFrame(now) {
  if (state.kind !== "xr") requestAnimationFrame(drawFrame);
  if (!renderer || !stream.extras) return;
  const canvas = $("view"), px = Math.min(devicePixelRatio, 2) * resolution;
  const w = Math.round(canvas.clientWidth * px), h = Math.round(canvas.clientHeight * px);
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
  const frame = stream.sample(now);
  if (!frame) return;
  renderer.draw(frame, stream.extras);
  countFrame(frame.step, performance.now());  // not rAF's time: that is the frame's start, before the message came
}

function countFrame(step, now) {
  const view = window.ppView;
  if (step !== view.step) { view.drawLog.push([step, performance.timeOrigin + now]); if (view.drawLog.length > 4000) view.drawLog.shift(); }
  view.drawn += 1; view.step = step; fpsCount += 1;
  if (now - fpsStart >= 1000) {
    view.fps = (1000 * fpsCount) / (now - fpsStart); fpsCount = 0; fpsStart = now;
    if (view.fps < 40 && resolution > MIN_RESOLUTION) resolution = Math.max(MIN_RESOLUTION, resolution * 0.85);
    else if (view.fps > 55 && resolution < 1) resolution = Math.min(1, resolution / 0.85);
    view.resolution = resolution;
    $("fps").textContent = "view: " + view.fps.toFixed(0) + " fps, step " + step + (resolution < 1 ? ", " + Math.round(100 * resolution) + " % resolution" : "");
  }
}

async function startXR() {
  const session = await navigator.xr.requestSession("immersive-ar", { requiredFeatures: ["local"],
    optionalFeatures: ["hit-test", "dom-overlay"], domOverlay: { root: document.body } });
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
    countFrame(shown.step, time);
  };
  session.addEventListener("end", () => {
    state.kind = "orientation"; state.sensor = "orientation"; state.placement = null; document.body.classList.remove("ar");
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
