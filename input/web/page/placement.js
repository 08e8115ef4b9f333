// PuppetPhone AR placement: where the field stands on the real floor (WebXR immersive-ar).
// A hit test gives a point on the floor in the session's "local" space; the field's origin goes
// there, turned about the vertical so its +Z (the side the game's camera looks from) faces the
// player. From then on the page sends its pose in field coordinates (the engine's world), and draws
// the field through the viewer's view matrix times field → local.
"use strict";

// The placement of the field from a floor hit and the viewer's position (both in local space).
function placeField(hitPosition, viewerPosition) {
  const dx = viewerPosition[0] - hitPosition[0], dz = viewerPosition[2] - hitPosition[2];
  const yaw = Math.hypot(dx, dz) > 1e-6 ? Math.atan2(dx, dz) : 0;
  return { origin: hitPosition.slice(0, 3), yaw };
}

// Field -> local as a column-major 4x4 (rotation about Y by yaw, then the origin).
function fieldToLocalMatrix(placement) {
  const c = Math.cos(placement.yaw), s = Math.sin(placement.yaw), o = placement.origin;
  return new Float32Array([c, 0, -s, 0, 0, 1, 0, 0, s, 0, c, 0, o[0], o[1], o[2], 1]);
}

// A pose in local space (q: x, y, z, w; p: metres) as a pose in field coordinates.
function localToField(placement, q, p) {
  const h = -placement.yaw / 2, ry = [0, Math.sin(h), 0, Math.cos(h)];
  const d = [p[0] - placement.origin[0], p[1] - placement.origin[1], p[2] - placement.origin[2]];
  const c = Math.cos(-placement.yaw), s = Math.sin(-placement.yaw);
  const pf = [c * d[0] + s * d[2], d[1], -s * d[0] + c * d[2]];
  const [ax, ay, az, aw] = ry, [bx, by, bz, bw] = q;
  const qf = [aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
    aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz];
  return { q: qf, p: pf };
}

if (typeof module !== "undefined") module.exports = { placeField, fieldToLocalMatrix, localToField };
