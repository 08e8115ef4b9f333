// PuppetPhone web controller: the phone's browser becomes the MotionStick.
// Streams one JSON reading per sensor event over a WebSocket (format: input/web/protocol.py).
// Plain script, no build step; served by the engine over HTTPS (sensors need a secure context).
"use strict";

const $ = (id) => document.getElementById(id);
const token = new URLSearchParams(location.search).get("t") || "";
const clock = () => performance.timeOrigin + performance.now();

const state = {
  ws: null, seq: 0, touch: false, jump: false, cal: false, crouch: 0,
  o: [0, 0, 0], acc: null, rot: null, kind: "orientation", q: null, p: null,
  sensor: "none", lastSent: 0, taken: false, rtt: null,
};

function setState(text, cls) { const el = $("state"); el.textContent = text; el.className = "state " + cls; }
function setMode() {
  const names = { xr: "WebXR 6-DoF (immersive-ar)", orientation: "orientation 3-DoF", none: "no motion sensor: touch only" };
  $("mode").textContent = "mode: " + names[state.sensor];
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
  if (state.kind === "xr") { r.q = state.q; r.p = state.p; } else { r.o = state.o; }
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
  state.ws = ws;
  ws.onopen = () => setState("connected", "on");
  ws.onmessage = (ev) => {
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
}

async function startXR() {
  const session = await navigator.xr.requestSession("immersive-ar", { optionalFeatures: ["dom-overlay"], domOverlay: { root: document.body } });
  const canvas = document.createElement("canvas");
  const gl = canvas.getContext("webgl", { xrCompatible: true });
  session.updateRenderState({ baseLayer: new XRWebGLLayer(session, gl) });
  const space = await session.requestReferenceSpace("local");
  state.kind = "xr"; state.sensor = "xr"; setMode();
  $("start").hidden = true;
  const frame = (time, xrFrame) => {
    const pose = xrFrame.getViewerPose(space);
    if (pose) {
      const t = pose.transform, o = t.orientation, p = t.position;
      state.q = [o.x, o.y, o.z, o.w]; state.p = [p.x, p.y, p.z];
      sendReading();
    }
    session.requestAnimationFrame(frame);
  };
  session.addEventListener("end", () => { state.kind = "orientation"; state.sensor = "orientation"; setMode(); });
  session.requestAnimationFrame(frame);
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
$("calibrate").addEventListener("click", () => { state.cal = true; sendReading(); });
$("enable").addEventListener("click", enableSensors);
$("xr").addEventListener("click", () => startXR().catch((err) => { $("status").textContent = "AR: " + err; }));

if (navigator.xr && navigator.xr.isSessionSupported) {
  navigator.xr.isSessionSupported("immersive-ar").then((ok) => { $("xr").hidden = !ok; }).catch(() => {});
}
// Without sensor events (a desktop browser, a paused sensor) the controller still says it is there.
setInterval(() => { if (performance.now() - state.lastSent > 250) sendReading(); }, 250);
setInterval(() => send({ ping: clock() }), 1000);
setMode();
connect();
