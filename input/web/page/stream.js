// PuppetPhone scene stream: the GLB a page gets once, then delta-coded frames (input/web/scene_stream.py).
// The reader mirrors scene_stream.decode_frame. StreamDecoder runs in the stream worker (stream_worker.js),
// off the main thread that renders; SceneStream, on the main thread, keeps the newest two decoded frames
// and interpolates one frame behind the newest, so a late frame never stalls the picture (the last holds).
"use strict";

const KINDS = ["capsules", "spheres", "boxes", "lines", "points", "prints"];
const FRAME_VERSION = 2;
const HEADER_BYTES = 48;

// The scene and the first rows, from the GLB the server sends on connect.
function readSceneGlb(buffer) {
  const dv = new DataView(buffer);
  if (dv.getUint32(0, true) !== 0x46546c67) throw new Error("not a GLB");
  const jsLen = dv.getUint32(12, true);
  const doc = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 20, jsLen)));
  const binStart = 20 + jsLen + 8;
  const extras = doc.scenes[0].extras.puppetphone;
  const rows = {}, scales = {};
  for (const kind of KINDS) {
    const info = extras.rows[kind];
    scales[kind] = info.scales;
    if (info.accessor === null) { rows[kind] = new Int16Array(0); continue; }
    const view = doc.bufferViews[doc.accessors[info.accessor].bufferView];
    rows[kind] = new Int16Array(buffer.slice(binStart + view.byteOffset, binStart + view.byteOffset + view.byteLength));
  }
  let marks = null;
  if (extras.marks) {
    const m = extras.marks, view = doc.bufferViews[doc.accessors[m.accessor].bufferView];
    marks = { nx: m.nx, nz: m.nz, x0: m.x0, z0: m.z0, cell: m.cell,
      cells: new Uint8Array(buffer.slice(binStart + view.byteOffset, binStart + view.byteOffset + view.byteLength)) };
  }
  const cam = extras.camera;
  return { extras, scales, state: { step: extras.step, published: 0, camera: { p: cam.position, q: cam.rotation, fov: cam.fov_y }, rows, marks } };
}

// The state after one frame, from the state the page held (``base``).
function decodeFrame(base, scales, buffer) {
  const dv = new DataView(buffer);
  if (buffer.byteLength < HEADER_BYTES || dv.getUint8(0) !== 0x50 || dv.getUint8(1) !== 0x46 || dv.getUint8(2) !== FRAME_VERSION)
    throw new Error("not a version " + FRAME_VERSION + " scene frame");
  const step = dv.getUint32(4, true), published = dv.getFloat64(8, true);
  const f = (i) => dv.getFloat32(16 + 4 * i, true);
  const camera = { p: [f(0), f(1), f(2)], q: [f(3), f(4), f(5), f(6)], fov: f(7) };
  let at = HEADER_BYTES;
  const rows = {};
  for (const kind of KINDS) {
    const cols = scales[kind].length;
    const n = dv.getUint16(at, true), mode = dv.getUint8(at + 2);
    at += 3;
    const old = base.rows[kind], out = new Int16Array(n * cols);
    out.set(old.subarray(0, Math.min(n, old.length / cols) * cols));
    if (mode) {
      const columns = dv.getUint16(at, true);
      at += 2;
      const mask = new Uint8Array(buffer, at, (n + 7) >> 3);
      at += mask.length;
      for (let r = 0; r < n; r++) {
        if (!(mask[r >> 3] & (1 << (r & 7)))) continue;
        for (let c = 0; c < cols; c++) {
          if (!(columns & (1 << c))) continue;
          if (mode === 1) { out[r * cols + c] += dv.getInt8(at); at += 1; }
          else { out[r * cols + c] = dv.getInt16(at, true); at += 2; }
        }
      }
    }
    rows[kind] = out;
  }
  const [marks, end] = decodeMarks(base.marks, dv, at);
  if (end !== buffer.byteLength) throw new Error("bytes after the tracks");
  return { step, published, camera, rows, marks };
}

// The tracks after a frame's tracks part at ``at`` (scene_stream._decode_marks): the same object when
// unchanged, so a reader can tell a change by identity.
function decodeMarks(base, dv, at) {
  const mode = dv.getUint8(at);
  at += 1;
  if (mode === 0) return [null, at];
  if (mode === 1) { if (!base) throw new Error("unchanged tracks, but the page has none"); return [base, at]; }
  const nx = dv.getUint16(at, true), nz = dv.getUint16(at + 2, true);
  const x0 = dv.getFloat32(at + 4, true), z0 = dv.getFloat32(at + 8, true), cell = dv.getFloat32(at + 12, true);
  at += 16;
  const cells = new Uint8Array(nx * nz);
  if (base && base.nx === nx && base.nz === nz && base.x0 === x0 && base.z0 === z0 && base.cell === cell) cells.set(base.cells);
  const bytes = new Uint8Array(dv.buffer, dv.byteOffset);
  if (mode === 2) {
    const r0 = dv.getUint16(at, true), c0 = dv.getUint16(at + 2, true), h = dv.getUint16(at + 4, true), w = dv.getUint16(at + 6, true);
    at += 8;
    if (r0 + h > nz || c0 + w > nx) throw new Error("tracks rectangle outside the grid");
    for (let r = 0; r < h; r++) cells.set(bytes.subarray(at + r * w, at + (r + 1) * w), (r0 + r) * nx + c0);
    at += h * w;
  } else if (mode === 3) {
    const count = dv.getUint32(at, true);
    at += 4;
    for (let i = 0; i < count; i++) {
      const k = dv.getUint32(at + 4 * i, true);
      if (k >= nx * nz) throw new Error("tracks cell outside the grid");
      cells[k] = bytes[at + 4 * count + i];
    }
    at += 5 * count;
  } else throw new Error("unknown tracks mode " + mode);
  return [{ nx, nz, x0, z0, cell, cells }, at];
}

// The tracks blurred by one cell ([1 2 1] both ways, edges repeated), as the desktop does before it
// uploads them (engine/render/environment.py soften_marks): with bilinear filtering, a soft groove
// with no cell corners, for one texture read per pixel. Done once per change, off the drawing thread.
function softenMarks(marks) {
  if (!marks) return marks;
  const { nx, nz, cells } = marks, rows = new Float32Array(nx * nz), out = new Uint8Array(nx * nz);
  for (let r = 0; r < nz; r++) {
    const up = Math.max(r - 1, 0) * nx, me = r * nx, down = Math.min(r + 1, nz - 1) * nx;
    for (let c = 0; c < nx; c++) rows[me + c] = 0.25 * cells[up + c] + 0.5 * cells[me + c] + 0.25 * cells[down + c];
  }
  for (let r = 0; r < nz; r++) {
    const me = r * nx;
    for (let c = 0; c < nx; c++) {
      const v = 0.25 * rows[me + Math.max(c - 1, 0)] + 0.5 * rows[me + c] + 0.25 * rows[me + Math.min(c + 1, nx - 1)];
      out[me + c] = Math.min(255, Math.floor(v + 0.5));
    }
  }
  return { ...marks, cells: out };
}

// Quantised rows to float rows (metres, colours in [0, 1]).
function toFloat(rows, scales) {
  const out = {};
  for (const kind of KINDS) {
    const s = scales[kind], src = rows[kind], dst = new Float32Array(src.length), cols = s.length;
    for (let i = 0; i < src.length; i++) dst[i] = src[i] / s[i % cols];
    out[kind] = dst;
  }
  return out;
}

function nlerpQuat(a, b, t) {
  const d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3], s = d < 0 ? -1 : 1;
  const q = [0, 1, 2, 3].map((i) => a[i] * (1 - t) + s * b[i] * t);
  const n = Math.hypot(q[0], q[1], q[2], q[3]) || 1;
  return q.map((v) => v / n);
}

// The worker's half (stream_worker.js): the quantised state a page holds, and each message as a
// frame of float rows ready to draw. ``receive`` returns that frame; ``extras`` only with a GLB.
class StreamDecoder {
  constructor() { this.scales = null; this.extras = null; this.state = null; this.received = 0; this.bytes = 0; }

  receive(buffer) {
    let state, extras = null;
    if (new DataView(buffer).getUint32(0, true) === 0x46546c67) {
      const glb = readSceneGlb(buffer);
      this.scales = glb.scales; this.extras = extras = glb.extras; state = glb.state;
    } else {
      if (!this.state) throw new Error("a frame before the scene");
      state = decodeFrame(this.state, this.scales, buffer);
    }
    this.state = state;
    this.received += 1; this.bytes += buffer.byteLength;
    return { extras, step: state.step, published: state.published * 1000, camera: state.camera,
      rows: toFloat(state.rows, this.scales), marks: state.marks, received: this.received, bytes: this.bytes };
  }
}

// The main thread's half: the newest two frames, blended by arrival time at each drawing.
class SceneStream {
  constructor() { this.extras = null; this.prev = null; this.cur = null; this.marks = null; this.marksVersion = 0; this.log = []; this.frames = 0; this.bytes = 0; }

  // Forget the scene (a new connection starts from a new GLB).
  reset() { this.extras = null; this.prev = null; this.cur = null; this.marks = null; this.marksVersion += 1; }

  // One decoded frame, given to the page at ``now`` (ms, performance.now()).
  accept(frame, now) {
    if (frame.extras) { this.extras = frame.extras; this.prev = null; this.cur = null; }
    if (!this.extras) return;
    const interval = this.cur ? Math.min(Math.max(now - this.cur.arrived, 1000 / 60), 100) : 1000 / 60;
    this.prev = this.cur;
    this.cur = { rows: frame.rows, camera: frame.camera, arrived: now, interval, step: frame.step };
    this.frames = frame.received; this.bytes = frame.bytes;
    // The tracks come only when they changed (undefined: as before; null: none).
    if (frame.marks !== undefined) { this.marks = frame.marks; this.marksVersion += 1; }
    // [step, published, reached the worker, decoded in the worker, available here]: ms since the epoch.
    if (frame.published) this.log.push([frame.step, frame.published, frame.arrived, frame.decoded, performance.timeOrigin + now]);
    if (this.log.length > 4000) this.log.shift();
  }

  // One binary message decoded here, on the calling thread (node tests, a page without workers).
  receive(decoder, buffer, now) {
    const frame = decoder.receive(buffer);
    frame.arrived = frame.decoded = performance.timeOrigin + now;
    if (frame.marks !== this.rawMarks) { this.rawMarks = frame.marks; frame.marks = softenMarks(frame.marks); } else frame.marks = undefined;
    this.accept(frame, now);
    return frame.step;
  }
  // The rows and camera to draw at ``now`` (ms): prev → cur over the arrival interval.
  sample(now) {
    const cur = this.cur, prev = this.prev;
    if (!cur) return null;
    const marks = this.marks, marksVersion = this.marksVersion;
    if (!prev) return { rows: cur.rows, camera: cur.camera, step: cur.step, marks, marksVersion };
    const t = Math.min(Math.max((now - cur.arrived) / cur.interval, 0), 1);
    const rows = {};
    for (const kind of KINDS) {
      const a = prev.rows[kind], b = cur.rows[kind];
      if (a.length !== b.length || t >= 1) { rows[kind] = b; continue; }
      const out = new Float32Array(b.length);
      for (let i = 0; i < b.length; i++) out[i] = a[i] + (b[i] - a[i]) * t;
      rows[kind] = out;
    }
    const p = [0, 1, 2].map((i) => prev.camera.p[i] + (cur.camera.p[i] - prev.camera.p[i]) * t);
    return { rows, camera: { p, q: nlerpQuat(prev.camera.q, cur.camera.q, t), fov: cur.camera.fov }, step: cur.step, marks, marksVersion };
  }
}

if (typeof module !== "undefined") module.exports = { SceneStream, StreamDecoder, decodeFrame, decodeMarks, softenMarks, readSceneGlb, toFloat, KINDS };
