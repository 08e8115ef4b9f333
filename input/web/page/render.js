// PuppetPhone page renderer: WebGL2, instanced, no library.
// Draws what the desktop's renderer draws from the same primitive rows (capsules, spheres, boxes,
// lines as thin capsules, points as small spheres) over a snowy ground and a sky gradient, lit by
// the scene's sun and a sky/ground hemisphere. In AR the sky and ground are left out: the camera
// image shows behind the scene.
"use strict";

// Lighting per vertex (Gouraud), finished to display colour there: the software rasteriser a phone-sized
// canvas is judged on (SwiftShader) pays per pixel, and the pixel stage is then one copy. Gamma 2 (squares
// and a square root) rather than 2.2.
const LIT = `
uniform vec3 sunDir; uniform vec3 sunColor; uniform float ambient; uniform vec3 eye;
uniform vec3 sky; uniform vec3 outlineColor;
vec3 lit(vec3 n, vec3 p, vec3 base, float outline) {
  n = normalize(n);
  float diff = max(dot(n, sunDir), 0.0);
  vec3 hemi = mix(vec3(0.52, 0.54, 0.58), sky * sky, 0.5 + 0.5 * n.y);
  vec3 c = base * (sunColor * diff * 0.55 + hemi * ambient * 1.1);
  float rim = 1.0 - abs(dot(n, normalize(eye - p)));
  c = mix(c, outlineColor * outlineColor, clamp(outline, 0.0, 1.0) * rim * rim * rim);
  return sqrt(c / (1.0 + c * 0.15));
}`;

const CAPSULE_VS = `#version 300 es
layout(location=0) in vec4 dirEnd;
layout(location=1) in vec3 a; layout(location=2) in vec3 b; layout(location=3) in float r;
layout(location=4) in vec3 col; layout(location=5) in float outline;
uniform mat4 viewProj;
out vec3 vColor;
${LIT}
void main() {
  vec3 ax = b - a; float len = length(ax);
  vec3 w = len > 1e-6 ? ax / len : vec3(0.0, 1.0, 0.0);
  vec3 t = abs(w.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
  vec3 u = normalize(cross(t, w)); vec3 v = cross(w, u);
  vec3 n = u * dirEnd.x + w * dirEnd.y + v * dirEnd.z;
  vec3 p = mix(a, b, dirEnd.w) + r * n;
  vColor = lit(n, p, col * col, outline);
  gl_Position = viewProj * vec4(p, 1.0);
}`;

const BOX_VS = `#version 300 es
layout(location=0) in vec3 corner; layout(location=6) in vec3 normal;
layout(location=1) in vec3 c; layout(location=2) in vec3 h; layout(location=3) in vec4 q;
layout(location=4) in vec3 col; layout(location=5) in float outline;
uniform mat4 viewProj;
out vec3 vColor;
${LIT}
vec3 rot(vec4 q, vec3 v) { vec3 u = q.yzw; return v + 2.0 * cross(u, cross(u, v) + q.x * v); }
void main() {
  vec3 p = c + rot(q, corner * h);
  vColor = lit(rot(q, normal), p, col * col, outline);
  gl_Position = viewProj * vec4(p, 1.0);
}`;

// Conifer tiers (engine/render/shaders.py CONE_VS): base centre a, apex b, base radius r; ``outline`` carries
// the snow on the tier, which whitens its upper side in a ragged band; the skirt's every other spoke hangs lower.
const CONE_VS = `#version 300 es
layout(location=0) in vec4 vert;  // cos, sin round the axis; height fraction; 1 on the base disc
layout(location=1) in vec3 a; layout(location=2) in vec3 b; layout(location=3) in float r;
layout(location=4) in vec3 col; layout(location=5) in float snowy;
uniform mat4 viewProj;
out vec3 vColor;
${LIT}
void main() {
  vec3 axis = b - a; float h = max(length(axis), 1e-6); vec3 y = axis / h;
  vec3 helper = abs(y.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
  vec3 x = normalize(cross(helper, y)); vec3 z = cross(x, y);
  float t = vert.z, seed = dot(a, vec3(12.9, 0.0, 78.2)), angle = atan(vert.y, vert.x);
  float spike = vert.w < 0.5 && t < 0.01 ? 0.5 + 0.5 * cos(angle * 9.0 + seed) : 0.0;
  vec3 radial = x * vert.x + z * vert.y;
  vec3 p = a + axis * t + radial * (r * (1.0 - t) * (1.0 + 0.12 * spike)) - y * (0.10 * h * spike);
  vec3 n = vert.w > 0.5 ? -y : normalize(radial * h + y * r);
  float snow = snowy * smoothstep(0.2, 0.5, t + 0.22 * sin(angle * 5.0 + seed) + 0.15 * spike);
  vec3 c = mix(col, vec3(0.93, 0.95, 0.99), snow);
  vColor = lit(n, p, c * c, 0.0);
  gl_Position = viewProj * vec4(p, 1.0);
}`;

// The falling snow (engine/render/snowfall.py): each flake placed from its start and phase by the time of
// the step shown (``fall``, ``swayA``, ``swayB``: the clock's terms, reduced on the CPU in double precision).
const FLAKE_VS = `#version 300 es
layout(location=0) in vec4 flake;
uniform mat4 viewProj; uniform float fall; uniform float height; uniform float sway; uniform vec2 phase;
uniform float size; uniform float focal; uniform vec3 eye; uniform vec3 color; uniform vec3 horizon;
flat out vec3 vColor;
void main() {
  vec3 p = vec3(flake.x + sway * sin(phase.x + flake.w), mod(flake.y - fall, height), flake.z + sway * cos(phase.y + flake.w));
  gl_Position = viewProj * vec4(p, 1.0);
  gl_PointSize = clamp(size * focal / max(gl_Position.w, 0.05), 1.0, 24.0);
  float fade = clamp(length(p - eye) / 35.0, 0.0, 1.0);
  vColor = mix(color, horizon, fade * fade);
}`;

// A round flake: its colour (faded to the horizon per flake, in the vertex stage), nothing outside its circle.
const FLAKE_FS = `#version 300 es
precision mediump float;
flat in vec3 vColor;
out vec4 frag;
void main() {
  vec2 d = gl_PointCoord - 0.5;
  if (dot(d, d) > 0.25) discard;
  frag = vec4(vColor, 1.0);
}`;

const FLAT_FS = `#version 300 es
precision mediump float;
in vec3 vColor; out vec4 frag;
void main() { frag = vec4(vColor, 1.0); }`;

// The ground as a disc of rings round the eye (groundDisc), out to where it has long faded into the horizon.
// A field of snow (no grid lines) is coloured per vertex, faded to the horizon there, and its pixels are a
// copy. Few, large triangles: the software rasteriser a phone-sized canvas is judged on (SwiftShader) pays
// per triangle as well as per pixel (a grid of 2 m cells, 3200 triangles, cost more than half the screen's
// pixels). Where a game draws grid lines, a pixel works them out (GRID_FS). The blob shadows, tracks and
// footprints go on afterwards, each over what it covers.
const GROUND_VS = `#version 300 es
layout(location=0) in vec2 around; uniform mat4 viewProj; uniform float height; uniform vec3 eye;
uniform vec3 color; uniform vec3 horizon;
out vec3 vColor;
void main() {
  float fade = clamp(length(around) / 35.0, 0.0, 1.0);
  vColor = mix(color, horizon, fade * fade);
  gl_Position = viewProj * vec4(eye.x + around.x, height, eye.z + around.y, 1.0);
}`;

const GRID_VS = `#version 300 es
layout(location=0) in vec2 around; uniform mat4 viewProj; uniform float height; uniform vec3 eye;
out vec2 vXZ; out float vFade;
void main() {
  vXZ = eye.xz + around;
  vFade = clamp(length(around) / 35.0, 0.0, 1.0);
  gl_Position = viewProj * vec4(vXZ.x, height, vXZ.y, 1.0);
}`;

// The ground's colour at ``xz`` with the grid lines (the same in GRID_FS and SHADOW_FS, so a shade is never
// lighter than the ground it falls on); PLAIN_COLOUR where the game draws none (the snow: every blob-shadow
// pixel would pay for the grid's test and derivatives).
const PLAIN_COLOUR = `
uniform vec3 color;
vec3 groundColour(vec2 xz, float fade) { return color; }`;
const GROUND_COLOUR = `
uniform vec3 color; uniform vec3 gridColor; uniform float gridStrength; uniform float spacing;
vec3 groundColour(vec2 xz, float fade) {
  if (gridStrength <= 0.0) return color;
  vec2 g = abs(fract(xz / spacing + 0.5) - 0.5) / fwidth(xz / spacing);
  return mix(color, gridColor, (1.0 - min(min(g.x, g.y), 1.0)) * gridStrength * (1.0 - fade));
}`;

const GRID_FS = `#version 300 es
precision highp float;
in vec2 vXZ; in float vFade; uniform vec3 horizon;
out vec4 frag;
${GROUND_COLOUR}
void main() { frag = vec4(mix(groundColour(vXZ, vFade), horizon, vFade * vFade), 1.0); }`;

// The sky's gradient per vertex of a dome of directions (skyDome), at infinity behind everything (depth 1,
// as the desktop's SKY_DOME_VS). Rings dense where the gradient is steep, just above the horizon, so a phone
// sees a few dozen triangles of it: a screen-covering grid (24², ~600 triangles in view) cost the software
// rasteriser more, and was further from the exact gradient (11 levels off at worst against 2).
const SKY_VS = `#version 300 es
layout(location=0) in vec3 dir; uniform mat4 viewProj; uniform vec3 sky; uniform vec3 horizon;
out vec3 vColor;
void main() {
  vColor = mix(horizon, sky, pow(clamp(dir.y, 0.0, 1.0), 0.45));
  gl_Position = (viewProj * vec4(dir, 0.0)).xyww;
}`;

// Blob shadows: each round thing (capsule, sphere; a box as its footprint's circle) cast along the sun
// onto the ground as a soft stadium, drawn over the ground as a quad round that stadium. A pixel works out
// the ground's colour in that much shade (blue-tinted: the sky's light stays) and the blending keeps the
// darker of it and what is there (MIN): where limbs overlap the deepest shade wins and nothing darkens twice,
// with no mask to render and no texture for the ground to read.
const SHADOW_VS = `#version 300 es
layout(location=0) in vec2 corner;
layout(location=1) in vec3 a; layout(location=2) in vec3 b; layout(location=3) in float r;
uniform mat4 viewProj; uniform vec3 sunDir; uniform float height; uniform vec3 eye;
out vec2 vXZ; out float vFade; flat out vec2 vA; flat out vec2 vB; flat out float vR; flat out float vSoft; flat out float vStrength;
vec2 onGround(vec3 p) { return p.xz - sunDir.xz * (max(p.y - height, 0.0) / sunDir.y); }
void main() {
  vec2 pa = onGround(a), pb = onGround(b);
  float lift = max(min(a.y, b.y) - r - height, 0.0);
  vSoft = 0.35 * r + 0.25 * lift; vR = r; vA = pa; vB = pb;
  vStrength = clamp(1.0 - lift / 3.0, 0.25, 1.0);
  vec2 ax = pb - pa; float len = length(ax);
  vec2 u = len > 1e-5 ? ax / len : vec2(1.0, 0.0), v = vec2(-u.y, u.x);
  float e = r + vSoft;
  vXZ = mix(pa, pb, 0.5 + 0.5 * corner.x) + u * corner.x * e + v * corner.y * e;
  vFade = clamp(length(vXZ - eye.xz) / 35.0, 0.0, 1.0);
  gl_Position = viewProj * vec4(vXZ.x, height, vXZ.y, 1.0);
}`;

const SHADOW_FS = (ground) => `#version 300 es
precision highp float;
in vec2 vXZ; in float vFade; flat in vec2 vA; flat in vec2 vB; flat in float vR; flat in float vSoft; flat in float vStrength;
uniform vec3 horizon; uniform vec3 shadowTint;
out vec4 frag;
${ground}
void main() {
  vec2 ab = vB - vA; float t = clamp(dot(vXZ - vA, ab) / max(dot(ab, ab), 1e-8), 0.0, 1.0);
  float m = vStrength * (1.0 - smoothstep(vR - vSoft, vR + vSoft, length(vXZ - vA - ab * t)));
  frag = vec4(mix(groundColour(vXZ, vFade) * mix(vec3(1.0), shadowTint, m), horizon, vFade * vFade), 1.0);
}`;

// Decals over the ground (multiplied in: blend dst·src·2, so 0.5 keeps the colour), as on the desktop:
// the tracks in the snow and the footprints (engine/render/shaders_ground.py's MARKS_FS and PRINT_FS).
const DECAL_VS = `#version 300 es
layout(location=0) in vec2 corner;
uniform mat4 viewProj; uniform vec4 rect; uniform float height;
out vec3 vP; out vec2 vUV;
void main() { vUV = corner; vP = vec3(rect.x + corner.x * rect.z, height, rect.y + corner.y * rect.w); gl_Position = viewProj * vec4(vP, 1.0); }`;

// A shaded track cell's factor 1 (the snow's own colour) as a byte: up to 255 / MARKS_ONE (the sunlit wall).
const MARKS_ONE = 200;

const MARKS_FS = `#version 300 es
precision highp float;
#define MARKS_ONE ${MARKS_ONE}.0
in vec3 vP; in vec2 vUV;
uniform sampler2D marks; uniform vec4 uvRect; uniform vec3 eye;
out vec4 frag;
// The grid comes shaded per cell (marksShade: the groove's tint and its slope in the sun, as the desktop's
// MARKS_FS works them out per pixel): one read per pixel.
void main() {
  vec3 k = texture(marks, uvRect.xy + vUV * uvRect.zw).rgb * (255.0 / MARKS_ONE);
  float fade = clamp(length(vP.xz - eye.xz) / 35.0, 0.0, 1.0);
  frag = vec4(0.5 * mix(k, vec3(1.0), fade * fade), 1.0);
}`;

const PRINT_VS = `#version 300 es
layout(location=0) in vec2 corner;
layout(location=1) in vec2 xz; layout(location=2) in vec2 dir; layout(location=3) in vec2 half_; layout(location=4) in float strength;
uniform mat4 viewProj; uniform float height;
out vec3 vP; out vec2 vLocal; out float vStrength; out vec2 vDir;
void main() {
  vec2 side = vec2(-dir.y, dir.x);
  vec2 p = xz + dir * (corner.x * half_.x) + side * (corner.y * half_.y);
  vP = vec3(p.x, height, p.y); vLocal = corner; vStrength = strength; vDir = dir;
  gl_Position = viewProj * vec4(vP, 1.0);
}`;

const PRINT_FS = `#version 300 es
precision highp float;
in vec3 vP; in vec2 vLocal; in float vStrength; in vec2 vDir;
uniform vec3 sunDir; uniform vec3 eye;
out vec4 frag;
void main() {
  vec2 ball = (vLocal - vec2(0.38, 0.0)) / vec2(0.58, 0.95);
  vec2 heel = (vLocal - vec2(-0.55, 0.0)) / vec2(0.42, 0.72);
  float f = max(1.0 - dot(ball, ball), 1.0 - dot(heel, heel));
  if (f <= 0.0) discard;
  float m = smoothstep(0.0, 0.45, f);
  vec2 g = dot(ball, ball) < dot(heel, heel) ? -ball / vec2(0.58, 0.95) : -heel / vec2(0.42, 0.72);
  vec2 gw = vDir * g.x + vec2(-vDir.y, vDir.x) * g.y;
  float wall = m * (1.0 - m) * 4.0;
  float k = 1.0 - 0.12 * m + 0.25 * wall * dot(normalize(gw + 1e-5), normalize(sunDir.xz + 1e-5));
  float fade = clamp(length(vP.xz - eye.xz) / 35.0, 0.0, 1.0);
  k = mix(1.0, k, vStrength * (1.0 - fade * fade));
  frag = vec4(vec3(0.5 * k) * vec3(0.97, 0.985, 1.0), 1.0);
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

// A unit cone (engine/render/env_meshes.py cone_mesh): side rings from base to apex, and the base disc.
function coneMesh(segments = 16, rings = 4) {
  const v = [], idx = [];
  for (let i = 0; i <= rings; i++) for (let k = 0; k < segments; k++) {
    const a = (2 * Math.PI * k) / segments; v.push(Math.cos(a), Math.sin(a), i / rings, 0);
  }
  for (let i = 0; i < rings; i++) for (let k = 0; k < segments; k++) {
    const p = i * segments + k, q = i * segments + ((k + 1) % segments);
    idx.push(p, q, p + segments, q, q + segments, p + segments);
  }
  const centre = v.length / 4;
  v.push(0, 0, 0, 1);
  for (let k = 0; k < segments; k++) { const a = (2 * Math.PI * k) / segments; v.push(Math.cos(a), Math.sin(a), 0, 1); }
  for (let k = 0; k < segments; k++) idx.push(centre, centre + 1 + k, centre + 1 + ((k + 1) % segments));
  return { vertices: new Float32Array(v), indices: new Uint16Array(idx) };
}

// The ground round the eye: rings at ``radii`` (metres; the first 0, the centre), ``segments`` round, as
// offsets (x, z) from the eye, and triangles. Small rings under the eye: a triangle from right below the
// camera out to 5 m, clipped at the near plane, got its depth wrong in SwiftShader (the ground hid the
// puppet's legs); then rings every 5 m while the ground fades (the fade's square, interpolated linearly
// along 5 m, is off by under a thousandth), and one far out.
function groundDisc(radii = [0, 0.5, 1.5, 3, 5, 10, 15, 20, 25, 30, 35, 60], segments = 24) {
  const v = [0, 0], idx = [];
  for (let i = 1; i < radii.length; i++) for (let k = 0; k < segments; k++) {
    const a = (2 * Math.PI * k) / segments;
    v.push(radii[i] * Math.cos(a), radii[i] * Math.sin(a));
  }
  const at = (ring, k) => (ring === 0 ? 0 : 1 + (ring - 1) * segments + (k % segments));
  for (let i = 0; i < radii.length - 1; i++) for (let k = 0; k < segments; k++) {
    if (i === 0) { idx.push(0, at(1, k), at(1, k + 1)); continue; }
    idx.push(at(i, k), at(i + 1, k), at(i + 1, k + 1), at(i, k), at(i + 1, k + 1), at(i, k + 1));
  }
  return { vertices: new Float32Array(v), indices: new Uint16Array(idx) };
}

// The sky dome: unit directions in rings at ``elevations`` (degrees; below the horizon the sky is the
// horizon's colour, for what the ground disc leaves), ``segments`` round, and triangles. The gradient,
// pow(height, 0.45), is steepest at the horizon: the rings are spaced so interpolating between them is off by
// under 2 % of the sky-to-horizon difference anywhere.
function skyDome(elevations = [-90, -5, 0, 0.1, 0.3, 0.6, 1, 1.6, 2.5, 3.7, 5.3, 7.5, 10.5, 14.5, 20, 27, 36, 48, 63, 90], segments = 24) {
  const v = [], idx = [];
  for (const e of elevations) {
    const r = (e * Math.PI) / 180;
    for (let k = 0; k < segments; k++) { const a = (2 * Math.PI * k) / segments; v.push(Math.cos(r) * Math.cos(a), Math.sin(r), Math.cos(r) * Math.sin(a)); }
  }
  for (let i = 0; i < elevations.length - 1; i++) for (let k = 0; k < segments; k++) {
    const p = i * segments + k, q = i * segments + ((k + 1) % segments);
    idx.push(p, q, p + segments, q, q + segments, p + segments);
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

// The six planes (a, b, c, d: inside where a·x + b·y + c·z + d ≥ 0, normalised) of a view-projection's frustum.
function frustumPlanes(m) {
  const row = (i) => [m[i], m[4 + i], m[8 + i], m[12 + i]], w = row(3), planes = [];
  for (const i of [0, 1, 2]) for (const s of [1, -1]) {
    const r = row(i), p = [0, 1, 2, 3].map((k) => w[k] + s * r[k]), n = Math.hypot(p[0], p[1], p[2]) || 1;
    planes.push(p.map((v) => v / n));
  }
  return planes;
}

// The rows of ``rows`` (``stride`` floats: end a, end b, radius first) whose bounding sphere meets the
// frustum: the software rasteriser shades every vertex of every instance, on screen or not, and a phone
// looks at a few of the field's trees and puppets at a time. ``grow`` widens a row's radius (a cone's skirt).
function cull(rows, stride, planes, grow = 1) {
  const n = rows.length / stride, keep = [];
  for (let i = 0; i < n; i++) {
    const o = i * stride, cx = (rows[o] + rows[o + 3]) / 2, cy = (rows[o + 1] + rows[o + 4]) / 2, cz = (rows[o + 2] + rows[o + 5]) / 2;
    const rad = Math.hypot(rows[o + 3] - rows[o], rows[o + 4] - rows[o + 1], rows[o + 5] - rows[o + 2]) / 2 + grow * rows[o + 6];
    if (planes.every((p) => p[0] * cx + p[1] * cy + p[2] * cz + p[3] >= -rad)) keep.push(i);
  }
  if (keep.length === n) return rows;
  const out = new Float32Array(keep.length * stride);
  keep.forEach((i, k) => out.set(rows.subarray(i * stride, (i + 1) * stride), k * stride));
  return out;
}

// What a full shadow leaves of the snow's colour, per channel: the sun's share of its light goes, the blue
// sky's stays (as the desktop's ground shadow; colours squared and rooted for gamma 2).
function shadowTint(look) {
  const s = look.sun, d = s.direction, up = Math.max(d[1] / Math.hypot(d[0], d[1], d[2]), 0);
  return [0, 1, 2].map((i) => {
    const sun = s.color[i] * s.intensity * up, sky = look.sky[i] * look.sky[i] * s.ambient * 1.6;
    return Math.sqrt(1 - 0.9 * sun / (sun + sky));
  });
}

// The softened tracks ``soft`` (stream.js softenInto) shaded per cell into ``out`` (RGBA bytes, MARKS_ONE =
// the snow's own colour), as the desktop's MARKS_FS shades each pixel: the groove tinted blue by its depth,
// and its walls lit by the sun along their slope (neighbouring cells, edges repeated); an untouched cell is
// exactly 1. Redoes the cells whose slope the softened cells ``soft`` changed at [r0, c0, r1, c1) reach (one
// cell round them) and returns that region.
function shadeMarks(soft, out, nx, nz, region, sun) {
  const len = Math.hypot(sun[0], sun[1], sun[2]), sx = sun[0] / len, sy = sun[1] / len, sz = sun[2] / len;
  const r0 = Math.max(region[0] - 1, 0), c0 = Math.max(region[1] - 1, 0), r1 = Math.min(region[2] + 1, nz), c1 = Math.min(region[3] + 1, nx);
  const smooth = (e, x) => { const t = Math.min(Math.max(x / e, 0), 1); return t * t * (3 - 2 * t); };
  const tint = [0.76, 0.82, 0.92];
  for (let r = r0; r < r1; r++) for (let c = c0; c < c1; c++) {
    const i = r * nx + c, m = soft[i] / 255;
    let k = [1, 1, 1];
    if (m >= 0.01) {
      const gx = ((soft[r * nx + Math.min(c + 1, nx - 1)] - soft[r * nx + Math.max(c - 1, 0)]) / 255) * 1.6;
      const gz = ((soft[Math.min(r + 1, nz - 1) * nx + c] - soft[Math.max(r - 1, 0) * nx + c]) / 255) * 1.6;
      const n = Math.hypot(gx, 1, gz), light = Math.min(Math.max(Math.max((gx * sx + sy + gz * sz) / n, 0) / Math.max(sy, 0.2), 0.72), 1.12);
      const deep = smooth(1, m), lit = 1 + (light - 1) * smooth(0.4, m);
      k = tint.map((t) => (1 + (t - 1) * deep) * lit);
    }
    for (let j = 0; j < 3; j++) out[4 * i + j] = Math.min(255, Math.round(k[j] * MARKS_ONE));
    out[4 * i + 3] = 255;
  }
  return [r0, c0, r1, c1];
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
    this.capsule = compile(gl, CAPSULE_VS, FLAT_FS);
    this.box = compile(gl, BOX_VS, FLAT_FS);
    this.ground = compile(gl, GROUND_VS, FLAT_FS);
    this.grid = compile(gl, GRID_VS, GRID_FS);
    this.sky = compile(gl, SKY_VS, FLAT_FS);
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
    const ground = groundDisc();
    this.buffer(ground.vertices); gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 2, gl.FLOAT, false, 8, 0);
    const gb = gl.createBuffer(); gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, gb); gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, ground.indices, gl.STATIC_DRAW);
    this.groundCount = ground.indices.length;
    this.skyVao = gl.createVertexArray(); gl.bindVertexArray(this.skyVao);
    const sky = skyDome();
    this.buffer(sky.vertices); gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 12, 0);
    const sb = gl.createBuffer(); gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, sb); gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, sky.indices, gl.STATIC_DRAW);
    this.skyCount = sky.indices.length;
    this.shadow = compile(gl, SHADOW_VS, SHADOW_FS(PLAIN_COLOUR)); this.gridShadow = compile(gl, SHADOW_VS, SHADOW_FS(GROUND_COLOUR));
    this.marksProg = compile(gl, DECAL_VS, MARKS_FS);
    this.printProg = compile(gl, PRINT_VS, PRINT_FS);
    const square = new Float32Array([-1, -1, 1, -1, -1, 1, 1, 1]);
    this.shadowVao = gl.createVertexArray(); gl.bindVertexArray(this.shadowVao);
    this.buffer(square); gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 2, gl.FLOAT, false, 8, 0);
    this.shadowInst = this.instances([3, 3, 1, 3, 1]);
    this.printVao = gl.createVertexArray(); gl.bindVertexArray(this.printVao);
    this.buffer(square); gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 2, gl.FLOAT, false, 8, 0);
    this.printInst = this.instances([2, 2, 2, 1]);
    this.decalVao = gl.createVertexArray(); gl.bindVertexArray(this.decalVao);
    this.buffer(new Float32Array([0, 0, 1, 0, 0, 1, 1, 1])); gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 2, gl.FLOAT, false, 8, 0);
    gl.bindVertexArray(null);
    this.cone = compile(gl, CONE_VS, FLAT_FS);
    const cone = coneMesh();
    this.coneVao = gl.createVertexArray(); gl.bindVertexArray(this.coneVao);
    this.buffer(cone.vertices); gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 4, gl.FLOAT, false, 16, 0);
    const cb = gl.createBuffer(); gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, cb); gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, cone.indices, gl.STATIC_DRAW);
    this.coneCount = cone.indices.length;
    this.coneInst = this.instances([3, 3, 1, 3, 1]);
    this.flake = compile(gl, FLAKE_VS, FLAKE_FS);
    this.flakeVao = gl.createVertexArray(); gl.bindVertexArray(this.flakeVao);
    this.flakeBuf = this.buffer(new Float32Array(4)); gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 4, gl.FLOAT, false, 16, 0);
    this.flakes = null;
    gl.bindVertexArray(null);
    this.casters = { key: [], rows: new Float32Array(0) };
    this.marksTex = null; this.marksSrc = null; this.marksSoft = null; this.marksShade = null; this.marksSun = null; this.marksRect = null;
    this.uploaded = new Map(); this.round = { key: [], rows: new Float32Array(0) };
  }

  // ``data`` into the array buffer ``buf``, unless it is the very array uploaded there last (unchanged rows).
  upload(buf, data) {
    const gl = this.gl;
    gl.bindBuffer(gl.ARRAY_BUFFER, buf);
    if (this.uploaded.get(buf) === data) return;
    this.uploaded.set(buf, data);
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.DYNAMIC_DRAW);
  }

  // The round rows of ``rows`` (roundRows), rebuilt only when one of the kinds they come from changed.
  roundOf(rows) {
    const key = [rows.capsules, rows.spheres, rows.lines, rows.points], c = this.round;
    if (!key.every((a, i) => a === c.key[i])) { c.key = key; c.rows = roundRows(rows); }
    return c.rows;
  }

  // An RGBA texture, linearly filtered, clamped at its edges.
  texture(w, h, data) {
    const gl = this.gl, tex = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, tex);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, w, h, 0, gl.RGBA, gl.UNSIGNED_BYTE, data);
    for (const [k, v] of [[gl.TEXTURE_MIN_FILTER, gl.LINEAR], [gl.TEXTURE_MAG_FILTER, gl.LINEAR],
      [gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE], [gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE]]) gl.texParameteri(gl.TEXTURE_2D, k, v);
    return tex;
  }

  // Every caster of a blob shadow as a capsule row (round rows, and each box as the circle round its
  // footprint), rebuilt only when the rows it comes from changed.
  castersOf(round, boxes) {
    const c = this.casters;
    if (c.key[0] === round && c.key[1] === boxes) return c.rows;
    const nb = boxes.length / 14, casters = new Float32Array(round.length + 11 * nb);
    casters.set(round);
    for (let i = 0, at = round.length; i < nb; i++, at += 11) {
      const o = i * 14;
      casters.set(boxes.subarray(o, o + 3), at); casters.set(boxes.subarray(o, o + 3), at + 3);
      casters[at + 1] = casters[at + 4] = boxes[o + 1] - boxes[o + 4] + Math.hypot(boxes[o + 3], boxes[o + 5]);
      casters[at + 6] = Math.hypot(boxes[o + 3], boxes[o + 5]);
    }
    c.key = [round, boxes]; c.rows = casters;
    return casters;
  }

  // The blob shadows of ``casters`` (capsule rows) on the ground just drawn (SHADOW_VS): a quad each,
  // kept where darker (MIN), behind whatever stands in front (depth test, no depth writes).
  drawShadows(casters, look, viewProj, eye) {
    const n = casters.length / 11;
    if (!n) return;
    const gl = this.gl, d = look.sun.direction, len = Math.hypot(d[0], d[1], d[2]), g = look.ground;
    const p = g.grid ? this.gridShadow : this.shadow, u = p.u;
    gl.useProgram(p.prog);
    gl.uniformMatrix4fv(u.viewProj, false, viewProj);
    gl.uniform3f(u.sunDir, d[0] / len, Math.max(d[1] / len, 0.2), d[2] / len); gl.uniform1f(u.height, g.height);
    gl.uniform3fv(u.eye, eye); gl.uniform3fv(u.horizon, look.horizon); gl.uniform3fv(u.shadowTint, shadowTint(look));
    this.groundUniforms(u, g);
    gl.enable(gl.BLEND); gl.blendEquation(gl.MIN);
    gl.depthFunc(gl.LEQUAL); gl.depthMask(false);
    gl.enable(gl.POLYGON_OFFSET_FILL); gl.polygonOffset(-2, -8);
    gl.bindVertexArray(this.shadowVao);
    this.upload(this.shadowInst, casters);
    gl.drawArraysInstanced(gl.TRIANGLE_STRIP, 0, 4, n);
    gl.disable(gl.POLYGON_OFFSET_FILL); gl.blendEquation(gl.FUNC_ADD); gl.disable(gl.BLEND);
    gl.depthMask(true); gl.depthFunc(gl.LESS);
  }

  // The ground's colour and grid lines (GROUND_COLOUR) into a program's uniforms.
  groundUniforms(u, g) {
    const gl = this.gl;
    gl.uniform3fv(u.color, g.color);
    if (u.gridColor) {
      gl.uniform3fv(u.gridColor, g.grid_color); gl.uniform1f(u.gridStrength, g.grid ? g.grid_strength : 0);
      gl.uniform1f(u.spacing, g.grid_spacing);
    }
  }

  // The tracks' shaded texture (shadeMarks) and the rectangle of marked cells. A new grid is softened,
  // shaded and uploaded whole; the same grid with ``dirty`` cells ([row0, col0, row1, col1)) has only those
  // and the cells their blur and slope reach done again and re-uploaded (a ball rolling changes a few cells
  // a step, not the 240 × 240 grid).
  updateMarks(marks, dirty, sun) {
    const gl = this.gl;
    if (marks !== this.marksSrc || (marks && sun !== this.marksSun)) {
      if (this.marksTex) gl.deleteTexture(this.marksTex);
      this.marksTex = null; this.marksRect = null; this.marksSrc = marks; this.marksSoft = null; this.marksShade = null; this.marksBox = null;
      if (!marks) return;
      this.marksSun = sun;
      this.marksSoft = new Uint8Array(marks.nx * marks.nz); this.marksShade = new Uint8Array(4 * marks.nx * marks.nz);
      dirty = softenInto(marks.cells, this.marksSoft, marks.nx, marks.nz, [0, 0, marks.nz, marks.nx]);
      shadeMarks(this.marksSoft, this.marksShade, marks.nx, marks.nz, dirty, sun);
      this.marksTex = this.texture(marks.nx, marks.nz, this.marksShade);
    } else if (marks && dirty) {
      const [r0, c0, r1, c1] = shadeMarks(this.marksSoft, this.marksShade, marks.nx, marks.nz,
        softenInto(marks.cells, this.marksSoft, marks.nx, marks.nz, dirty), sun);
      gl.bindTexture(gl.TEXTURE_2D, this.marksTex);
      gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1); gl.pixelStorei(gl.UNPACK_ROW_LENGTH, marks.nx);
      gl.pixelStorei(gl.UNPACK_SKIP_ROWS, r0); gl.pixelStorei(gl.UNPACK_SKIP_PIXELS, c0);
      gl.texSubImage2D(gl.TEXTURE_2D, 0, c0, r0, c1 - c0, r1 - r0, gl.RGBA, gl.UNSIGNED_BYTE, this.marksShade);
      gl.pixelStorei(gl.UNPACK_ROW_LENGTH, 0); gl.pixelStorei(gl.UNPACK_SKIP_ROWS, 0); gl.pixelStorei(gl.UNPACK_SKIP_PIXELS, 0);
    } else return;
    // The marked cells' bounds grow by what the changed cells hold (a filled cell keeps them: drawn, discarded).
    let [r0, c0, r1, c1] = this.marksBox || [marks.nz, marks.nx, -1, -1];
    const cells = marks.cells;
    for (let r = dirty[0]; r < dirty[2]; r++) for (let c = dirty[1]; c < dirty[3]; c++) {
      if (cells[r * marks.nx + c] > 5) { if (r < r0) r0 = r; if (r > r1) r1 = r; if (c < c0) c0 = c; if (c > c1) c1 = c; }
    }
    if (r1 < 0) return;
    this.marksBox = [r0, c0, r1, c1];
    const cell = marks.cell;
    this.marksRect = { marks, rect: [marks.x0 + (c0 - 1) * cell, marks.z0 + (r0 - 1) * cell, (c1 - c0 + 3) * cell, (r1 - r0 + 3) * cell] };
  }

  // Tracks and footprints over the ground just drawn (objects in front keep their pixels: depth test).
  drawDecals(frame, look, viewProj, eye) {
    const gl = this.gl, g = look.ground.height, d = look.sun.direction, len = Math.hypot(d[0], d[1], d[2]);
    const prints = frame.rows.prints || new Float32Array(0);
    if (!this.marksRect && !prints.length) return;
    gl.enable(gl.BLEND); gl.blendFunc(gl.DST_COLOR, gl.SRC_COLOR);
    gl.depthFunc(gl.LEQUAL); gl.depthMask(false);
    gl.enable(gl.POLYGON_OFFSET_FILL); gl.polygonOffset(-2, -8);
    if (this.marksRect) {
      const { marks, rect } = this.marksRect, p = this.marksProg, u = p.u, w = marks.cell * marks.nx, h = marks.cell * marks.nz;
      gl.useProgram(p.prog);
      gl.activeTexture(gl.TEXTURE1); gl.bindTexture(gl.TEXTURE_2D, this.marksTex); gl.uniform1i(u.marks, 1);
      gl.uniformMatrix4fv(u.viewProj, false, viewProj); gl.uniform4fv(u.rect, rect); gl.uniform1f(u.height, g);
      gl.uniform4f(u.uvRect, (rect[0] - marks.x0) / w, (rect[1] - marks.z0) / h, rect[2] / w, rect[3] / h);
      gl.uniform3fv(u.eye, eye);
      gl.bindVertexArray(this.decalVao); gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4);
      gl.activeTexture(gl.TEXTURE0);
    }
    if (prints.length) {
      const p = this.printProg, u = p.u;
      gl.useProgram(p.prog);
      gl.uniformMatrix4fv(u.viewProj, false, viewProj); gl.uniform1f(u.height, g);
      gl.uniform3f(u.sunDir, d[0] / len, d[1] / len, d[2] / len); gl.uniform3fv(u.eye, eye);
      gl.bindVertexArray(this.printVao);
      this.upload(this.printInst, prints);
      gl.drawArraysInstanced(gl.TRIANGLE_STRIP, 0, 4, prints.length / 7);
    }
    gl.disable(gl.POLYGON_OFFSET_FILL); gl.disable(gl.BLEND);
    gl.depthMask(true); gl.depthFunc(gl.LESS);
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
    let proj, view, eye;
    const round = this.roundOf(frame.rows);
    if (!xr) this.updateMarks(frame.marks, frame.marksDirty, look.sun.direction);
    if (xr) {
      ({ proj, view, eye } = xr);
      gl.viewport(...xr.viewport);
    } else {
      const w = this.canvas.width, h = this.canvas.height, cam = frame.camera;
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      gl.viewport(0, 0, w, h);
      proj = perspective(cam.fov, w / h, 0.05, 200); view = viewMatrix(cam.p, cam.q); eye = cam.p;
    }
    const viewProj = mul4(proj, view), planes = frustumPlanes(viewProj);
    gl.enable(gl.DEPTH_TEST); gl.disable(gl.CULL_FACE);
    // The magic window's sky and ground cover every pixel: only the depth is cleared there.
    if (xr && xr.first) { gl.clearColor(0, 0, 0, 0); gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT); }
    else if (!xr) gl.clear(gl.DEPTH_BUFFER_BIT);
    const shown = cull(round, 11, planes);
    if (shown.length) {
      gl.useProgram(this.capsule.prog);
      gl.uniformMatrix4fv(this.capsule.u.viewProj, false, viewProj);
      this.lighting(this.capsule, look, eye);
      gl.bindVertexArray(this.capVao);
      this.upload(this.capInst, shown);
      // A capsule is closed, so its far side is never seen: culled before the rasteriser sets it up (the
      // software one pays per triangle; a close-up puppet is ~4000). CAPSULE_VS maps the mesh's axes to (u, w, v),
      // a mirror, so its outside faces come out clockwise.
      gl.enable(gl.CULL_FACE); gl.frontFace(gl.CW);
      gl.drawElementsInstanced(gl.TRIANGLES, this.capCount, gl.UNSIGNED_SHORT, 0, shown.length / 11);
      gl.disable(gl.CULL_FACE); gl.frontFace(gl.CCW);
    }
    const boxes = frame.rows.boxes;
    if (boxes.length) {
      gl.useProgram(this.box.prog);
      gl.uniformMatrix4fv(this.box.u.viewProj, false, viewProj);
      this.lighting(this.box, look, eye);
      gl.bindVertexArray(this.boxVao);
      this.upload(this.boxInst, boxes);
      gl.drawArraysInstanced(gl.TRIANGLES, 0, 36, boxes.length / 14);
    }
    const cones = cull(frame.rows.cones || new Float32Array(0), 11, planes, 1.3);
    if (cones.length) {
      gl.useProgram(this.cone.prog);
      gl.uniformMatrix4fv(this.cone.u.viewProj, false, viewProj);
      this.lighting(this.cone, look, eye);
      gl.bindVertexArray(this.coneVao);
      this.upload(this.coneInst, cones);
      gl.drawElementsInstanced(gl.TRIANGLES, this.coneCount, gl.UNSIGNED_SHORT, 0, cones.length / 11);
    }
    if (!xr) this.backdrop(frame, look, viewProj, eye, round);
    gl.bindVertexArray(null);
  }

  // Ground, then sky, after the objects: the depth test skips every pixel they already cover. The blob
  // shadows of ``round`` rows and the boxes, the tracks and footprints go on the ground in between.
  backdrop(frame, look, viewProj, eye, round) {
    const gl = this.gl, g = look.ground, p = g.grid ? this.grid : this.ground, u = p.u;
    gl.useProgram(p.prog);
    gl.bindVertexArray(this.groundVao);
    gl.uniformMatrix4fv(u.viewProj, false, viewProj); gl.uniform1f(u.height, g.height);
    gl.uniform3fv(u.eye, eye); gl.uniform3fv(u.horizon, look.horizon);
    this.groundUniforms(u, g);
    gl.drawElements(gl.TRIANGLES, this.groundCount, gl.UNSIGNED_SHORT, 0);
    this.drawShadows(this.castersOf(round, frame.rows.boxes), look, viewProj, eye);
    this.drawDecals(frame, look, viewProj, eye);
    gl.useProgram(this.sky.prog);
    gl.uniformMatrix4fv(this.sky.u.viewProj, false, viewProj);
    gl.uniform3fv(this.sky.u.sky, look.sky); gl.uniform3fv(this.sky.u.horizon, look.horizon);
    gl.depthFunc(gl.LEQUAL); gl.depthMask(false);
    gl.bindVertexArray(this.skyVao); gl.drawElements(gl.TRIANGLES, this.skyCount, gl.UNSIGNED_SHORT, 0);
    gl.depthFunc(gl.LESS);
    if (look.snowfall) this.drawSnowfall(frame, look, viewProj, eye);
    gl.depthMask(true);
  }

  // The falling snow over everything drawn (hidden by what is in front: depth test, no depth writes), at the
  // time of the step shown; the flakes go to the GPU once per scene.
  drawSnowfall(frame, look, viewProj, eye) {
    const gl = this.gl, f = look.snowfall, u = this.flake.u;
    if (this.flakes !== f.flakes) { this.flakes = f.flakes; this.upload(this.flakeBuf, f.flakes); }
    const time = frame.time * f.step_seconds, turn = 2 * Math.PI;
    gl.useProgram(this.flake.prog);
    gl.uniformMatrix4fv(u.viewProj, false, viewProj);
    gl.uniform1f(u.fall, (f.speed * time) % f.height); gl.uniform1f(u.height, f.height); gl.uniform1f(u.sway, f.sway);
    gl.uniform2f(u.phase, (f.sway_rates[0] * time) % turn, (f.sway_rates[1] * time) % turn);
    gl.uniform1f(u.size, f.size); gl.uniform1f(u.focal, this.canvas.height / 2 / Math.tan((frame.camera.fov * Math.PI) / 360));
    gl.uniform3fv(u.eye, eye); gl.uniform3fv(u.color, f.color); gl.uniform3fv(u.horizon, look.horizon);
    gl.bindVertexArray(this.flakeVao);
    gl.drawArrays(gl.POINTS, 0, f.count);
  }
}

// Frames drawn, the step on screen and when each step was first drawn, frames per second, and the
// resolution scale: a phone (or a software renderer) that cannot keep 40 fps draws fewer pixels,
// stretched, rather than fewer frames. Used by whichever thread draws (the view worker, or the main
// thread in AR and where a worker cannot draw).
class FrameCounter {
  constructor() { this.drawn = 0; this.step = -1; this.fps = 0; this.resolution = 1; this.held = null; this.drawLog = []; this.ticks = 0; this.since = null; }

  // Keep the resolution at ``r`` (the bench measures the full resolution's frame rate); null: adapt again.
  hold(r) { this.held = r; if (r !== null) this.resolution = r; this.ticks = 0; this.since = null; }

  // One frame drawn at ``now`` (ms, performance.now()) showing ``step``; true when ``fps`` was renewed.
  count(step, now) {
    if (step !== this.step) { this.drawLog.push([step, performance.timeOrigin + now]); if (this.drawLog.length > 4000) this.drawLog.shift(); }
    this.drawn += 1; this.step = step; this.ticks += 1;
    if (this.since === null) this.since = now;
    if (now - this.since < 1000) return false;
    this.fps = (1000 * this.ticks) / (now - this.since); this.ticks = 0; this.since = now;
    if (this.held !== null) return true;
    if (this.fps < 40 && this.resolution > MIN_RESOLUTION) this.resolution = Math.max(MIN_RESOLUTION, this.resolution * 0.85);
    else if (this.fps > 55 && this.resolution < 1) this.resolution = Math.min(1, this.resolution / 0.85);
    return true;
  }
}
// Never under three quarters of the device's pixels a side: a phone that draws fewer is not showing the scene
// "at" its size any more (half a side is a quarter of the pixels), and the page says the scale it drew at.
const MIN_RESOLUTION = 0.75;

if (typeof module !== "undefined") module.exports = { PageRenderer, FrameCounter, MIN_RESOLUTION, shadeMarks, MARKS_ONE, groundDisc, skyDome, capsuleMesh, perspective, viewMatrix, quatToMat3, mul4, roundRows, frustumPlanes, cull };
