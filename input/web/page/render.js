// PuppetPhone page renderer: WebGL2, instanced, no library.
// Draws what the desktop's renderer draws from the same primitive rows (capsules, spheres, boxes,
// lines as thin capsules, points as small spheres) over a snowy ground and a sky gradient, lit by
// the scene's sun and a sky/ground hemisphere. In AR the sky and ground are left out: the camera
// image shows behind the scene.
"use strict";

const CAPSULE_VS = `#version 300 es
layout(location=0) in vec4 dirEnd;
layout(location=1) in vec3 a; layout(location=2) in vec3 b; layout(location=3) in float r;
layout(location=4) in vec3 col; layout(location=5) in float outline;
uniform mat4 viewProj;
out vec3 vN; out vec3 vP; out vec3 vC; out float vO;
void main() {
  vec3 ax = b - a; float len = length(ax);
  vec3 w = len > 1e-6 ? ax / len : vec3(0.0, 1.0, 0.0);
  vec3 t = abs(w.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
  vec3 u = normalize(cross(t, w)); vec3 v = cross(w, u);
  vec3 n = u * dirEnd.x + w * dirEnd.y + v * dirEnd.z;
  vec3 p = mix(a, b, dirEnd.w) + r * n;
  vN = n; vP = p; vC = col * col; vO = outline;
  gl_Position = viewProj * vec4(p, 1.0);
}`;

const BOX_VS = `#version 300 es
layout(location=0) in vec3 corner; layout(location=6) in vec3 normal;
layout(location=1) in vec3 c; layout(location=2) in vec3 h; layout(location=3) in vec4 q;
layout(location=4) in vec3 col; layout(location=5) in float outline;
uniform mat4 viewProj;
out vec3 vN; out vec3 vP; out vec3 vC; out float vO;
vec3 rot(vec4 q, vec3 v) { vec3 u = q.yzw; return v + 2.0 * cross(u, cross(u, v) + q.x * v); }
void main() {
  vec3 p = c + rot(q, corner * h);
  vN = rot(q, normal); vP = p; vC = col * col; vO = outline;
  gl_Position = viewProj * vec4(p, 1.0);
}`;

const LIT_FS = `#version 300 es
precision highp float;
in vec3 vN; in vec3 vP; in vec3 vC; in float vO;
uniform vec3 sunDir; uniform vec3 sunColor; uniform float ambient; uniform vec3 eye;
uniform vec3 sky; uniform vec3 horizon; uniform vec3 outlineColor;
out vec4 frag;
// Gamma 2 (squares and a square root) rather than 2.2: software GL on a phone-sized canvas is fill-bound.
void main() {
  vec3 n = normalize(vN);
  float diff = max(dot(n, sunDir), 0.0);
  vec3 hemi = mix(vec3(0.52, 0.54, 0.58), sky * sky, 0.5 + 0.5 * n.y);
  vec3 c = vC * (sunColor * diff * 0.55 + hemi * ambient * 1.1);
  float rim = 1.0 - abs(dot(n, normalize(eye - vP)));
  c = mix(c, outlineColor * outlineColor, clamp(vO, 0.0, 1.0) * rim * rim * rim);
  frag = vec4(sqrt(c / (1.0 + c * 0.15)), 1.0);
}`;

const GROUND_VS = `#version 300 es
layout(location=0) in vec2 xz; uniform mat4 viewProj; uniform float height; out vec3 vP;
void main() { vP = vec3(xz.x, height, xz.y); gl_Position = viewProj * vec4(vP, 1.0); }`;

const GROUND_FS = `#version 300 es
precision highp float;
in vec3 vP; uniform vec3 color; uniform vec3 gridColor; uniform float gridStrength; uniform float spacing;
uniform vec3 eye; uniform vec3 horizon; uniform float alpha;
out vec4 frag;
void main() {
  vec2 g = abs(fract(vP.xz / spacing + 0.5) - 0.5) / fwidth(vP.xz / spacing);
  float line = 1.0 - min(min(g.x, g.y), 1.0);
  float fade = clamp(length(vP.xz - eye.xz) / 35.0, 0.0, 1.0);
  vec3 c = mix(color, gridColor, line * gridStrength * (1.0 - fade));
  c = mix(c, horizon, fade * fade);
  frag = vec4(c, alpha);
}`;

const SKY_VS = `#version 300 es
const vec2 P[3] = vec2[3](vec2(-1.0, -1.0), vec2(3.0, -1.0), vec2(-1.0, 3.0));
out vec2 ndc; void main() { ndc = P[gl_VertexID]; gl_Position = vec4(ndc, 1.0, 1.0); }`;

const SKY_FS = `#version 300 es
precision highp float;
in vec2 ndc; uniform mat3 basis; uniform vec2 tanHalf; uniform vec3 sky; uniform vec3 horizon;
out vec4 frag;
void main() {
  vec3 d = normalize(basis * vec3(ndc * tanHalf, -1.0));
  frag = vec4(mix(horizon, sky, pow(clamp(d.y, 0.0, 1.0), 0.45)), 1.0);
}`;

function compile(gl, vs, fs) {
  const prog = gl.createProgram();
  for (const [type, src] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
    const sh = gl.createShader(type);
    gl.shaderSource(sh, src); gl.compileShader(sh);
    if (!gl.getShaderParameter(sh, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(sh));
    gl.attachShader(prog, sh);
  }
  gl.linkProgram(prog);
  if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
  const u = {};
  const n = gl.getProgramParameter(prog, gl.ACTIVE_UNIFORMS);
  for (let i = 0; i < n; i++) { const name = gl.getActiveUniform(prog, i).name; u[name] = gl.getUniformLocation(prog, name); }
  return { prog, u };
}

// A unit capsule: a sphere split at its equator, lower half at end a (w 0), upper at end b (w 1).
function capsuleMesh(seg = 10, rings = 3) {
  const v = [], idx = [];
  const ring = (lat, end) => { for (let j = 0; j <= seg; j++) { const lon = (j / seg) * 2 * Math.PI;
    v.push(Math.cos(lat) * Math.cos(lon), Math.sin(lat), Math.cos(lat) * Math.sin(lon), end); } };
  for (let i = 0; i <= rings; i++) ring(-Math.PI / 2 + (i / rings) * (Math.PI / 2), 0);
  for (let i = 0; i <= rings; i++) ring((i / rings) * (Math.PI / 2), 1);
  const count = 2 * (rings + 1);
  for (let i = 0; i < count - 1; i++) for (let j = 0; j < seg; j++) {
    const k = i * (seg + 1) + j, l = k + seg + 1;
    idx.push(k, l, k + 1, k + 1, l, l + 1);
  }
  return { vertices: new Float32Array(v), indices: new Uint16Array(idx) };
}

function boxMesh() {
  const v = [];
  const faces = [[0, 1], [0, -1], [1, 1], [1, -1], [2, 1], [2, -1]];
  for (const [axis, s] of faces) {
    const n = [0, 0, 0]; n[axis] = s;
    const u = (axis + 1) % 3, w = (axis + 2) % 3;
    const corner = (cu, cw) => { const p = [0, 0, 0]; p[axis] = s; p[u] = cu; p[w] = cw; v.push(...p, ...n); };
    corner(-1, -1); corner(1, -1); corner(1, 1); corner(-1, -1); corner(1, 1); corner(-1, 1);
  }
  return new Float32Array(v);
}

// Column-major 4x4 helpers.
function perspective(fovY, aspect, near, far) {
  const t = 1 / Math.tan((fovY * Math.PI) / 360), m = new Float32Array(16);
  m[0] = t / aspect; m[5] = t; m[10] = -(far + near) / (far - near); m[11] = -1; m[14] = (-2 * far * near) / (far - near);
  return m;
}
function quatToMat3(q) { // (w, x, y, z) -> row-major 3x3 as rows r[i][j]
  const [w, x, y, z] = q;
  return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
    [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
    [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]];
}
function viewMatrix(p, q) { // camera -> world (p, q); the view is its inverse
  const r = quatToMat3(q), m = new Float32Array(16);
  for (let i = 0; i < 3; i++) for (let j = 0; j < 3; j++) m[j * 4 + i] = r[j][i];
  for (let i = 0; i < 3; i++) m[12 + i] = -(r[0][i] * p[0] + r[1][i] * p[1] + r[2][i] * p[2]);
  m[15] = 1;
  return m;
}
function mul4(a, b) {
  const m = new Float32Array(16);
  for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) {
    let s = 0; for (let k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k]; m[c * 4 + r] = s;
  }
  return m;
}

// Every round thing as one capsule row a[3] b[3] r colour[3] outline: capsules, spheres, lines, points.
function roundRows(rows) {
  const caps = rows.capsules, sph = rows.spheres, lines = rows.lines, pts = rows.points;
  const nl = lines.length / 10, np = pts.length / 8;
  const out = new Float32Array(caps.length + sph.length + 11 * (nl + np));
  out.set(caps, 0); out.set(sph, caps.length);
  let at = caps.length + sph.length;
  for (let i = 0; i < nl; i++, at += 11) {
    const l = lines.subarray(i * 10, i * 10 + 10);
    out.set(l.subarray(0, 6), at); out[at + 6] = 0.003 * l[9]; out.set(l.subarray(6, 9), at + 7);
  }
  for (let i = 0; i < np; i++, at += 11) {
    const p = pts.subarray(i * 8, i * 8 + 8);
    out.set(p.subarray(0, 3), at); out.set(p.subarray(0, 3), at + 3);
    out[at + 6] = p[7] > 0.5 ? 0.004 * p[3] : 0.5 * p[3]; out.set(p.subarray(4, 7), at + 7);
  }
  return out;
}

class PageRenderer {
  constructor(canvas, options = {}) {
    const gl = canvas.getContext("webgl2", { antialias: false, alpha: false, desynchronized: true, xrCompatible: !!options.xrCompatible });
    if (!gl) throw new Error("WebGL2 is not available");
    this.gl = gl; this.canvas = canvas;
    this.capsule = compile(gl, CAPSULE_VS, LIT_FS);
    this.box = compile(gl, BOX_VS, LIT_FS);
    this.ground = compile(gl, GROUND_VS, GROUND_FS);
    this.sky = compile(gl, SKY_VS, SKY_FS);
    const mesh = capsuleMesh();
    this.capVao = gl.createVertexArray(); gl.bindVertexArray(this.capVao);
    this.buffer(mesh.vertices); gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 4, gl.FLOAT, false, 16, 0);
    const ib = gl.createBuffer(); gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib); gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, mesh.indices, gl.STATIC_DRAW);
    this.capCount = mesh.indices.length;
    this.capInst = this.instances([3, 3, 1, 3, 1]);
    this.boxVao = gl.createVertexArray(); gl.bindVertexArray(this.boxVao);
    this.buffer(boxMesh());
    gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 24, 0);
    gl.enableVertexAttribArray(6); gl.vertexAttribPointer(6, 3, gl.FLOAT, false, 24, 12);
    this.boxInst = this.instances([3, 3, 4, 3, 1]);
    this.groundVao = gl.createVertexArray(); gl.bindVertexArray(this.groundVao);
    this.groundBuf = this.buffer(new Float32Array(8));
    gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 2, gl.FLOAT, false, 8, 0);
    this.skyVao = gl.createVertexArray();
    gl.bindVertexArray(null);
  }

  buffer(data) {
    const gl = this.gl, buf = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, buf); gl.bufferData(gl.ARRAY_BUFFER, data, gl.DYNAMIC_DRAW);
    return buf;
  }

  // An instance buffer bound to locations 1.. with the given column widths (the current VAO's).
  instances(widths) {
    const gl = this.gl, buf = gl.createBuffer(), stride = 4 * widths.reduce((s, w) => s + w, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, buf);
    let off = 0;
    widths.forEach((w, i) => {
      gl.enableVertexAttribArray(i + 1); gl.vertexAttribPointer(i + 1, w, gl.FLOAT, false, stride, off);
      gl.vertexAttribDivisor(i + 1, 1); off += 4 * w;
    });
    return buf;
  }

  lighting(prog, look, eye) {
    const gl = this.gl, u = prog.u, s = look.sun;
    const d = s.direction, n = Math.hypot(d[0], d[1], d[2]);
    gl.uniform3f(u.sunDir, d[0] / n, d[1] / n, d[2] / n);
    gl.uniform3f(u.sunColor, s.color[0] * s.intensity, s.color[1] * s.intensity, s.color[2] * s.intensity);
    gl.uniform1f(u.ambient, s.ambient);
    gl.uniform3fv(u.eye, eye); gl.uniform3fv(u.sky, look.sky); gl.uniform3fv(u.horizon, look.horizon);
    gl.uniform3fv(u.outlineColor, look.outline);
  }

  // Draw ``frame`` ({rows, camera}) with the scene's ``look``; ``xr`` gives view/projection/eye/viewport
  // instead (``first``: the first view of the XR frame, which clears).
  draw(frame, look, xr = null) {
    const gl = this.gl;
    let proj, view, eye, basis;
    if (xr) {
      ({ proj, view, eye } = xr);
      gl.viewport(...xr.viewport);
    } else {
      const w = this.canvas.width, h = this.canvas.height, cam = frame.camera;
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      gl.viewport(0, 0, w, h);
      proj = perspective(cam.fov, w / h, 0.05, 200); view = viewMatrix(cam.p, cam.q); eye = cam.p;
      basis = quatToMat3(cam.q);
    }
    const viewProj = mul4(proj, view);
    gl.enable(gl.DEPTH_TEST); gl.disable(gl.CULL_FACE);
    if (!xr || xr.first) { gl.clearColor(0, 0, 0, 0); gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT); }
    const round = roundRows(frame.rows);
    if (round.length) {
      gl.useProgram(this.capsule.prog);
      gl.uniformMatrix4fv(this.capsule.u.viewProj, false, viewProj);
      this.lighting(this.capsule, look, eye);
      gl.bindVertexArray(this.capVao);
      gl.bindBuffer(gl.ARRAY_BUFFER, this.capInst); gl.bufferData(gl.ARRAY_BUFFER, round, gl.DYNAMIC_DRAW);
      gl.drawElementsInstanced(gl.TRIANGLES, this.capCount, gl.UNSIGNED_SHORT, 0, round.length / 11);
    }
    const boxes = frame.rows.boxes;
    if (boxes.length) {
      gl.useProgram(this.box.prog);
      gl.uniformMatrix4fv(this.box.u.viewProj, false, viewProj);
      this.lighting(this.box, look, eye);
      gl.bindVertexArray(this.boxVao);
      gl.bindBuffer(gl.ARRAY_BUFFER, this.boxInst); gl.bufferData(gl.ARRAY_BUFFER, boxes, gl.DYNAMIC_DRAW);
      gl.drawArraysInstanced(gl.TRIANGLES, 0, 36, boxes.length / 14);
    }
    if (!xr) this.backdrop(frame, look, viewProj, eye, basis);
    gl.bindVertexArray(null);
  }

  // Ground, then sky, after the objects: the depth test skips every pixel they already cover.
  backdrop(frame, look, viewProj, eye, basis) {
    const gl = this.gl;
    {
      const g = look.ground, half = 40;
      gl.useProgram(this.ground.prog);
      gl.bindVertexArray(this.groundVao);
      gl.bindBuffer(gl.ARRAY_BUFFER, this.groundBuf);
      gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([-half, -half, half, -half, -half, half, half, half]), gl.DYNAMIC_DRAW);
      const u = this.ground.u;
      gl.uniformMatrix4fv(u.viewProj, false, viewProj); gl.uniform1f(u.height, g.height);
      gl.uniform3fv(u.color, g.color); gl.uniform3fv(u.gridColor, g.grid_color);
      gl.uniform1f(u.gridStrength, g.grid ? g.grid_strength : 0); gl.uniform1f(u.spacing, g.grid_spacing);
      gl.uniform3fv(u.eye, eye); gl.uniform3fv(u.horizon, look.horizon); gl.uniform1f(u.alpha, 1);
      gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4);
    }
    const cam = frame.camera, aspect = this.canvas.width / this.canvas.height, t = Math.tan((cam.fov * Math.PI) / 360);
    gl.useProgram(this.sky.prog);
    gl.uniformMatrix3fv(this.sky.u.basis, false, new Float32Array([0, 1, 2].flatMap((c) => [basis[0][c], basis[1][c], basis[2][c]])));
    gl.uniform2f(this.sky.u.tanHalf, t * aspect, t);
    gl.uniform3fv(this.sky.u.sky, look.sky); gl.uniform3fv(this.sky.u.horizon, look.horizon);
    gl.depthFunc(gl.LEQUAL); gl.depthMask(false);
    gl.bindVertexArray(this.skyVao); gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.depthMask(true); gl.depthFunc(gl.LESS);
  }
}

// Frames drawn, the step on screen and when each step was first drawn, frames per second, and the
// resolution scale: a phone (or a software renderer) that cannot keep 40 fps draws fewer pixels,
// stretched, rather than fewer frames. Used by whichever thread draws (the stream worker, or the main
// thread in AR and where a worker cannot draw).
class FrameCounter {
  constructor() { this.drawn = 0; this.step = -1; this.fps = 0; this.resolution = 1; this.drawLog = []; this.ticks = 0; this.since = null; }

  // One frame drawn at ``now`` (ms, performance.now()) showing ``step``; true when ``fps`` was renewed.
  count(step, now) {
    if (step !== this.step) { this.drawLog.push([step, performance.timeOrigin + now]); if (this.drawLog.length > 4000) this.drawLog.shift(); }
    this.drawn += 1; this.step = step; this.ticks += 1;
    if (this.since === null) this.since = now;
    if (now - this.since < 1000) return false;
    this.fps = (1000 * this.ticks) / (now - this.since); this.ticks = 0; this.since = now;
    if (this.fps < 40 && this.resolution > MIN_RESOLUTION) this.resolution = Math.max(MIN_RESOLUTION, this.resolution * 0.85);
    else if (this.fps > 55 && this.resolution < 1) this.resolution = Math.min(1, this.resolution / 0.85);
    return true;
  }
}
const MIN_RESOLUTION = 0.5;

if (typeof module !== "undefined") module.exports = { PageRenderer, FrameCounter, perspective, viewMatrix, quatToMat3, mul4, roundRows };
