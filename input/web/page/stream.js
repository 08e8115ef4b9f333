// PuppetPhone scene stream: the GLB a page gets once, then delta-coded frames (input/web/scene_stream.py).
// The reader mirrors scene_stream.decode_frame. StreamDecoder runs in the stream worker (stream_worker.js),
// which holds the socket; Forwarder makes each frame a message for the thread that draws (render_worker.js,
// or the main thread in AR), and SceneStream, there, keeps the newest two frames: a frame one step after the
// last is shown as it is, frames further apart are interpolated one frame behind the newest, and a late frame
// never stalls the picture (the last holds). Nothing that did not change
// is copied: a kind a frame leaves alone keeps its array (the drawer sees the same object and uploads
// nothing), and the tracks go as the block of cells that changed.
"use strict";

const KINDS = ["capsules", "spheres", "boxes", "lines", "points", "prints", "cones"];
// Kinds drawn as sent, never blended between frames (they do not move: a print fades, a tree stands).
const STILL = new Set(["prints", "cones"]);
const FRAME_VERSION = 3;
const HEADER_BYTES = 48;
const MAX_MARKS_CELLS = 1 << 20;  // scene_stream.MAX_MARKS_CELLS

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
  if (extras.snowfall) {  // the flakes' start positions and phases: x y z phase per flake
    const f = extras.snowfall, view = doc.bufferViews[doc.accessors[f.accessor].bufferView];
    if (view.byteLength !== 16 * f.count) throw new Error("snowfall: " + view.byteLength + " bytes for " + f.count + " flakes");
    f.flakes = new Float32Array(buffer.slice(binStart + view.byteOffset, binStart + view.byteOffset + view.byteLength));
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
    const old = base.rows[kind];
    if (!mode && old.length === n * cols) { rows[kind] = old; continue; }  // untouched: the same array
    const out = new Int16Array(n * cols);
    out.set(old.subarray(0, Math.min(n, old.length / cols) * cols));
    if (mode) {
      const columns = dv.getUint16(at, true);
      if (mode > 2 || columns === 0 || columns >> cols) throw new Error("bad changed columns or mode in the " + kind);
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
  const [marks, end, dirty] = decodeMarks(base.marks, dv, at);
  if (end !== buffer.byteLength) throw new Error("bytes after the tracks");
  return { step, published, camera, rows, marks, marksDirty: dirty };
}

// The tracks after a frame's tracks part at ``at`` (scene_stream._decode_marks), where the part ends, and
// the cells that changed as [row0, col0, row1, col1) (null: none). Unchanged: the same object. A frame
// that changes cells of the same grid writes them into the grid the page holds (no copy of the grid).
function decodeMarks(base, dv, at) {
  const mode = dv.getUint8(at);
  at += 1;
  if (mode === 0) return [null, at, null];
  if (mode === 1) { if (!base) throw new Error("unchanged tracks, but the page has none"); return [base, at, null]; }
  const nx = dv.getUint16(at, true), nz = dv.getUint16(at + 2, true);
  const x0 = dv.getFloat32(at + 4, true), z0 = dv.getFloat32(at + 8, true), cell = dv.getFloat32(at + 12, true);
  at += 16;
  if (nx * nz > MAX_MARKS_CELLS || !Number.isFinite(x0) || !Number.isFinite(z0) || !(cell > 0 && cell < 1e3))
    throw new Error("tracks grid of " + nx + " x " + nz + " cells of " + cell + " m");
  const same = base && base.nx === nx && base.nz === nz && base.x0 === x0 && base.z0 === z0 && base.cell === cell;
  const cells = same ? base.cells : new Uint8Array(nx * nz);
  const bytes = new Uint8Array(dv.buffer, dv.byteOffset);
  let dirty;
  if (mode === 2) {
    const r0 = dv.getUint16(at, true), c0 = dv.getUint16(at + 2, true), h = dv.getUint16(at + 4, true), w = dv.getUint16(at + 6, true);
    at += 8;
    if (r0 + h > nz || c0 + w > nx) throw new Error("tracks rectangle outside the grid");
    if (at + h * w > dv.byteLength) throw new Error("frame ends inside its tracks");
    for (let r = 0; r < h; r++) cells.set(bytes.subarray(at + r * w, at + (r + 1) * w), (r0 + r) * nx + c0);
    at += h * w;
    dirty = [r0, c0, r0 + h, c0 + w];
  } else if (mode === 3) {
    const count = dv.getUint32(at, true);
    at += 4;
    if (at + 5 * count > dv.byteLength) throw new Error("frame ends inside its tracks");
    let r0 = nz, c0 = nx, r1 = 0, c1 = 0;
    for (let i = 0; i < count; i++) {
      const k = dv.getUint32(at + 4 * i, true);
      if (k >= nx * nz) throw new Error("tracks cell outside the grid");
      cells[k] = bytes[at + 4 * count + i];
      const r = Math.floor(k / nx), c = k - r * nx;
      if (r < r0) r0 = r; if (r >= r1) r1 = r + 1; if (c < c0) c0 = c; if (c >= c1) c1 = c + 1;
    }
    at += 5 * count;
    dirty = count ? [r0, c0, r1, c1] : null;
  } else throw new Error("unknown tracks mode " + mode);
  // A new grid: all of it is new. The same grid: the same object, its cells rewritten in place.
  return [same ? base : { nx, nz, x0, z0, cell, cells }, at, same ? dirty : [0, 0, nz, nx]];
}

// The union of two dirty rectangles [row0, col0, row1, col1) (null: nothing).
function unionRect(a, b) {
  if (!a) return b; if (!b) return a;
  return [Math.min(a[0], b[0]), Math.min(a[1], b[1]), Math.max(a[2], b[2]), Math.max(a[3], b[3])];
}

// The tracks blurred by one cell ([1 2 1] both ways, edges repeated), as the desktop does before it
// uploads them (engine/render/environment.py soften_marks): with bilinear filtering, a soft groove
// with no cell corners, for one texture read per pixel. ``softenInto`` redoes only the cells whose
// blur a change at [r0, c0, r1, c1) reaches (one cell round it), into ``out``, and returns that region.
function softenInto(cells, out, nx, nz, dirty) {
  const r0 = Math.max(dirty[0] - 1, 0), c0 = Math.max(dirty[1] - 1, 0), r1 = Math.min(dirty[2] + 1, nz), c1 = Math.min(dirty[3] + 1, nx);
  const col = (r, c) => { const up = Math.max(r - 1, 0) * nx, me = r * nx, down = Math.min(r + 1, nz - 1) * nx;
    return 0.25 * cells[up + c] + 0.5 * cells[me + c] + 0.25 * cells[down + c]; };
  for (let r = r0; r < r1; r++) {
    let left = col(r, Math.max(c0 - 1, 0)), mid = col(r, c0);
    for (let c = c0; c < c1; c++) {
      const right = col(r, Math.min(c + 1, nx - 1));
      out[r * nx + c] = Math.min(255, Math.floor(0.25 * left + 0.5 * mid + 0.25 * right + 0.5));
      left = mid; mid = right;
    }
  }
  return [r0, c0, r1, c1];
}

function softenMarks(marks) {
  if (!marks) return marks;
  const out = new Uint8Array(marks.nx * marks.nz);
  softenInto(marks.cells, out, marks.nx, marks.nz, [0, 0, marks.nz, marks.nx]);
  return { ...marks, cells: out };
}

// Quantised rows to float rows (metres, colours in [0, 1]); a kind whose quantised array is the one
// ``cache`` saw last keeps its float array (``cache``: {ints, floats} per kind, updated).
function toFloat(rows, scales, cache = null) {
  const out = {};
  for (const kind of KINDS) {
    const src = rows[kind];
    if (cache && cache.ints[kind] === src) { out[kind] = cache.floats[kind]; continue; }
    const s = scales[kind], dst = new Float32Array(src.length), cols = s.length;
    for (let i = 0; i < src.length; i++) dst[i] = src[i] / s[i % cols];
    out[kind] = dst;
    if (cache) { cache.ints[kind] = src; cache.floats[kind] = dst; }
  }
  return out;
}

function nlerpQuat(a, b, t) {
  const d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3], s = d < 0 ? -1 : 1;
  const q = [0, 1, 2, 3].map((i) => a[i] * (1 - t) + s * b[i] * t);
  const n = Math.hypot(q[0], q[1], q[2], q[3]) || 1;
  return q.map((v) => v / n);
}

// The quantised state a page holds, and each message as a frame of float rows ready to draw.
// ``receive`` returns that frame; ``extras`` only with a GLB. Kinds the frame left alone keep their arrays.
class StreamDecoder {
  constructor() { this.scales = null; this.extras = null; this.state = null; this.received = 0; this.bytes = 0; this.cache = null; }

  receive(buffer) {
    let state, extras = null, marksDirty = null;
    if (new DataView(buffer).getUint32(0, true) === 0x46546c67) {
      const glb = readSceneGlb(buffer);
      this.scales = glb.scales; this.extras = extras = glb.extras; state = glb.state;
      this.cache = { ints: {}, floats: {} };
      if (state.marks) marksDirty = [0, 0, state.marks.nz, state.marks.nx];
    } else {
      if (!this.state) throw new Error("a frame before the scene");
      state = decodeFrame(this.state, this.scales, buffer);
      marksDirty = state.marksDirty;
    }
    this.state = state;
    this.received += 1; this.bytes += buffer.byteLength;
    return { extras, step: state.step, published: state.published * 1000, camera: state.camera,
      rows: toFloat(state.rows, this.scales, this.cache), marks: state.marks, marksDirty, received: this.received, bytes: this.bytes };
  }
}

// Each frame as a message for a drawer on another thread: only the kinds whose rows changed since the frame
// that drawer last got (the rest it keeps), and of the tracks, the block of cells changed since (the whole
// grid when it is new to the drawer). ``note`` every decoded frame, sent or not: its changed cells count.
class Forwarder {
  constructor() { this.reset(); }

  // The drawer holds nothing (new drawer, new scene): the next message carries everything.
  reset() { this.sent = {}; this.marks = null; this.dirty = null; this.whole = true; }

  note(frame) { if (frame.extras) this.whole = true; else this.dirty = unionRect(this.dirty, frame.marksDirty); }

  message(frame, extras) {
    const rows = {};
    for (const kind of KINDS) {
      if (this.whole || frame.rows[kind] !== this.sent[kind]) rows[kind] = this.sent[kind] = frame.rows[kind];
    }
    const m = frame.marks;
    let marks;  // undefined: as before
    if (this.whole || m !== this.marks) marks = m ? { nx: m.nx, nz: m.nz, x0: m.x0, z0: m.z0, cell: m.cell, cells: m.cells.slice() } : null;
    else if (m && this.dirty) {
      const [r0, c0, r1, c1] = this.dirty, w = c1 - c0, block = new Uint8Array((r1 - r0) * w);
      for (let r = r0; r < r1; r++) block.set(m.cells.subarray(r * m.nx + c0, r * m.nx + c1), (r - r0) * w);
      marks = { nx: m.nx, nz: m.nz, x0: m.x0, z0: m.z0, cell: m.cell, patch: { rect: this.dirty, cells: block } };
    }
    const out = { extras: this.whole ? extras : null, step: frame.step, published: frame.published, camera: frame.camera, rows, marks,
      arrived: frame.arrived, decoded: frame.decoded, received: frame.received, bytes: frame.bytes, behind: !!frame.behind };
    this.marks = m; this.dirty = null; this.whole = false;
    return out;
  }
}

function sameGrid(a, b) { return !!a && !!b && a.nx === b.nx && a.nz === b.nz && a.x0 === b.x0 && a.z0 === b.z0 && a.cell === b.cell; }

// The drawing thread's half: the newest two frames, blended by arrival time at each drawing when they are
// more than a step apart, and the tracks with the cells changed since the last drawing.
class SceneStream {
  constructor() { this.reset(); this.log = []; this.frames = 0; this.bytes = 0; }

  // Forget the scene (a new connection starts from a new GLB).
  reset() { this.extras = null; this.prev = null; this.cur = null; this.marks = null; this.marksDirty = null; this.fresh = false; this.lastBlend = 1; }

  // One decoded frame, given to the page at ``now`` (ms, performance.now()).
  accept(frame, now) {
    if (frame.extras) { this.extras = frame.extras; this.prev = null; this.cur = null; }
    if (!this.extras) return;
    const interval = this.cur ? Math.min(Math.max(now - this.cur.arrived, 1000 / 60), 100) : 1000 / 60;
    // Kinds a forwarded frame leaves out are as in the frame before (the same arrays).
    const rows = frame.extras || !this.cur ? frame.rows : { ...this.cur.rows, ...frame.rows };
    this.prev = this.cur;
    this.cur = { rows, camera: frame.camera, arrived: now, interval, step: frame.step, behind: !!frame.behind };
    this.fresh = true;
    this.frames = frame.received; this.bytes = frame.bytes;
    // The tracks: undefined, as before; null, none; a patch of changed cells (forwarded) or the grid held
    // here with cells changed in place (decoded here): those cells; else a new grid.
    const m = frame.marks;
    if (m === undefined) { /* as before */ } else if (m && m.patch && sameGrid(this.marks, m) && !frame.extras) {
      const [r0, c0, r1, c1] = m.patch.rect, w = c1 - c0;
      for (let r = r0; r < r1; r++) this.marks.cells.set(m.patch.cells.subarray((r - r0) * w, (r - r0 + 1) * w), r * m.nx + c0);
      this.marksDirty = unionRect(this.marksDirty, m.patch.rect);
    } else if (m && m === this.marks && !frame.extras) this.marksDirty = unionRect(this.marksDirty, frame.marksDirty);
    else if (m && m.patch) { /* a patch for a grid this thread does not hold: wait for the whole grid */ }
    else { this.marks = m; this.marksDirty = null; }
    // [step, published, reached the socket's thread, decoded, available to the drawer]: ms since the epoch.
    if (frame.published) this.log.push([frame.step, frame.published, frame.arrived, frame.decoded, performance.timeOrigin + now]);
    if (this.log.length > 4000) this.log.shift();
  }

  // One binary message decoded here, on the calling thread (the view worker, node tests).
  receive(decoder, buffer, now) {
    const frame = decoder.receive(buffer);
    frame.arrived = frame.decoded = performance.timeOrigin + now;
    this.accept(frame, now);
    return frame;
  }

  // How far the picture at ``now`` is from prev to cur (1: cur). Frames a step apart (the engine's pace) have
  // nothing between them to show: cur at once, so a drawing made when a frame arrives shows that frame,
  // not the one before. Frames farther apart (the back-pressure gave a slow phone fewer) are blended over
  // their arrival interval: the newest shows one interval late, but the motion stays smooth. Not when the
  // gap is the drawer's own (``behind``: the stream worker replaced a frame it held for a drawer still
  // busy): blending then spent its few drawings on pictures older than the frame it had.
  blendOf(now) {
    const cur = this.cur, prev = this.prev;
    if (!prev || cur.behind || cur.step - prev.step <= 1) return 1;
    return Math.min(Math.max((now - cur.arrived) / cur.interval, 0), 1);
  }

  // Whether a drawing at ``now`` would show something not drawn yet: a frame that came since the last
  // ``sample``, or a blend still under way. The drawer does not draw the same picture twice.
  wants(now) { return !!this.cur && (this.fresh || this.lastBlend < 1 || this.blendOf(now) < 1); }

  // The rows and camera to draw at ``now`` (ms): prev → cur (``blendOf``); ``time``: the step shown,
  // fractional while blending; the tracks and the cells changed since the last call (taken).
  sample(now) {
    const cur = this.cur, prev = this.prev;
    if (!cur) return null;
    const marks = this.marks, marksDirty = this.marksDirty;
    this.marksDirty = null; this.fresh = false; this.lastBlend = this.blendOf(now);
    if (!prev) return { rows: cur.rows, camera: cur.camera, step: cur.step, time: cur.step, marks, marksDirty };
    const t = this.blendOf(now);
    const rows = {};
    for (const kind of KINDS) {
      const a = prev.rows[kind], b = cur.rows[kind];
      if (a === b || a.length !== b.length || t >= 1 || STILL.has(kind)) { rows[kind] = b; continue; }
      const out = new Float32Array(b.length);
      for (let i = 0; i < b.length; i++) out[i] = a[i] + (b[i] - a[i]) * t;
      rows[kind] = out;
    }
    const p = [0, 1, 2].map((i) => prev.camera.p[i] + (cur.camera.p[i] - prev.camera.p[i]) * t);
    return { rows, camera: { p, q: nlerpQuat(prev.camera.q, cur.camera.q, t), fov: cur.camera.fov }, step: cur.step,
      time: prev.step + (cur.step - prev.step) * t, marks, marksDirty };
  }
}

if (typeof module !== "undefined") module.exports = { SceneStream, StreamDecoder, Forwarder, decodeFrame, decodeMarks, softenMarks, softenInto, unionRect, readSceneGlb, toFloat, KINDS };
