"""GLSL 3.30 sources for the cheap environment: a per-vertex lit ground and sky, a far
ridge, the sun, and the decals laid on the ground (shadow, snow track, footprints).

Why per vertex: on llvmpipe the ground and the sky cover nearly every pixel, and their
per-pixel shading (noise fetch, lighting, fog, sky gradient) cost 54 % of a frame. Snow
light and fog vary slowly across a field, so they are computed once per vertex of a mesh
that is dense near the camera and sparse far away, and the fragment stage only writes
the interpolated colour: about the cost of a clear. What does vary quickly on the ground
(a shadow, a track, a footprint) covers a bounded part of it and is drawn there alone,
as a decal that modulates the colour underneath (blend ``dst·src·2``, so 0.5 keeps it).

Compiled after :data:`engine.render.shaders.LIGHTING` (and, for the per-pixel variants of
the ground, :data:`engine.render.shaders_env.BACKGROUND`).
"""

from __future__ import annotations

__all__ = [
    "GROUND_MESH_VS",
    "GROUND_MESH_FS",
    "NEAR_DETAIL",
    "SKY_DOME_VS",
    "COLOR_FS",
    "RIDGE_VS",
    "SUN_VS",
    "SUN_FS",
    "DECAL_VS",
    "SHADOW_DECAL_FS",
    "MARKS_FS",
    "PRINT_VS",
    "PRINT_FS",
]

# The ground mesh: rings around the camera (in_ring: unit direction xz, radius in metres).
GROUND_MESH_VS = """
uniform mat4 u_view_proj;
uniform vec3 u_center;
uniform float u_extent;
uniform float u_height;
uniform vec3 u_ground_lin;
uniform float u_snow;
uniform sampler2D u_noise;
in vec3 in_ring;
out vec3 v_pos;
out vec3 v_lin;
out vec3 v_color;
void main() {
    float radius = in_ring.z * u_extent;
    v_pos = vec3(u_center.x + in_ring.x * radius, u_height, u_center.z + in_ring.y * radius);
    float dist = length(u_eye - v_pos);
    // Broad drifts at vertex density (a coarser scale than the per-pixel detail).
    vec4 drift = textureLod(u_noise, v_pos.xz * 0.025, 0.0);
    vec2 slope = (drift.gb - 0.5) * (0.35 * u_snow);
    vec3 albedo = u_ground_lin * (1.0 - 0.03 * u_snow * (1.0 - drift.r));
    float ndl = max(u_sun_dir.y - dot(slope, u_sun_dir.xz), 0.0);
    vec3 c = albedo * (u_sky_lin * u_ambient + u_sun_color * ndl);
    v_lin = mix(c, u_horizon_lin * SKY_GAIN, fog_amount(dist));
    v_color = finish(v_lin);
    gl_Position = u_view_proj * vec4(v_pos, 1.0);
}
"""

NEAR_DETAIL = 14.0
"""Metres from the eye within which the ground's ``NEAR`` variant adds fine drifts and sparkle."""

# The ground's fragment stage. Plain: the vertex colour. PIXEL: the tone curve per pixel (every
# per-pixel variant has it). Quality high splits its detail in two, since llvmpipe runs a
# branch's fetches and arithmetic for every pixel of a draw that has it, taken or not:
# MASK reads the ground shadow (only when there is one) and NEAR adds fine drifts and
# sparkle within NEAR_DETAIL metres (only on the rings that come that close: see
# engine.render.environment). GRID: anti-aliased grid lines. PHOTO: the background photo.
GROUND_MESH_FS = """
uniform sampler2D u_noise;
uniform vec3 u_grid_lin;
uniform float u_snow;
uniform float u_grid_spacing;
uniform float u_grid_strength;
uniform sampler2D u_ground_mask;    // MASK: the ground shadow is read here, not drawn as a decal
uniform vec4 u_rect;
uniform float u_shadow_strength;
uniform vec3 u_shadow_take;         // MASK: the share of the light a shadow takes (see SHADOW_DECAL_FS)
in vec3 v_pos;
in vec3 v_lin;
in vec3 v_color;
out vec4 f_color;
void main() {
#ifdef PIXEL
    vec3 c = v_lin;
    vec3 to_eye = u_eye - v_pos;
    float dist = length(to_eye);
#ifdef MASK
    vec2 muv = (v_pos.xz - u_rect.xy) / u_rect.zw;
    if (u_shadow_strength > 0.0 && all(greaterThan(muv, vec2(0.0))) && all(lessThan(muv, vec2(1.0)))) {
        c *= 1.0 - texture(u_ground_mask, muv).r * u_shadow_take;
    }
#endif
#ifdef NEAR
    if (dist < NEAR_DETAIL) {
        float near = 1.0 - dist / NEAR_DETAIL;
        vec4 drift = texture(u_noise, v_pos.xz * 0.08);
        vec2 slope = (drift.gb - 0.5) * (0.6 * u_snow) * near;
        c *= 1.0 + (0.6 * dot(slope, -u_sun_dir.xz) - 0.03 * u_snow * (1.0 - drift.r)) * near;
        ivec2 cell = ivec2(floor(v_pos.xz * 45.0));
        vec4 rnd = texelFetch(u_noise, cell & 255, 0);
        if (rnd.a > 0.97) {
            vec3 cn = normalize(vec3(rnd.g - 0.5, 0.6, rnd.b - 0.5));
            float g = max(dot(reflect(-u_sun_dir, cn), to_eye / dist), 0.0);
            g = g * g; g = g * g; g = g * g; g = g * g; g = g * g;   // ^32
            c += u_sun_color * g * 1.5 * near * u_snow;
        }
    }
#endif
#ifdef GRID
    if (dist < 60.0) {
        vec2 gp = v_pos.xz / u_grid_spacing;
        vec2 w = fwidth(gp);
        vec2 gl = abs(fract(gp - 0.5) - 0.5) / max(w, 1e-4);
        float line = 1.0 - min(min(gl.x, gl.y), 1.0);
        float fade = clamp(1.0 - max(w.x, w.y) * 3.0, 0.0, 1.0) * (1.0 - fog_amount(dist));
        c = mix(c, u_grid_lin, line * u_grid_strength * fade);
    }
#endif
#ifdef PHOTO
    c = mix(photo_linear(), c, u_fade);
#endif
    f_color = vec4(finish(c), 1.0);
#else
    f_color = vec4(v_color, 1.0);
#endif
}
"""

# The sky: a sphere of directions around the eye at the far plane (depth 1: only where
# nothing was drawn), its gradient and sun halo per vertex.
SKY_DOME_VS = """
uniform mat4 u_view_proj;
in vec3 in_dir;
out vec3 v_color;
void main() {
    float t = clamp(in_dir.y, 0.0, 1.0);
    vec3 c = mix(u_horizon_lin, u_sky_lin, sqrt(t)) * SKY_GAIN;
    float s = max(dot(in_dir, u_sun_dir), 0.0);
    c += u_sun_color * exp2(12.0 * 1.4427 * (s - 1.0)) * 0.08;
    if (in_dir.y < 0.0) c = u_horizon_lin * SKY_GAIN;
    v_color = finish(c);
    gl_Position = (u_view_proj * vec4(in_dir, 0.0)).xyww;
}
"""

COLOR_FS = """
in vec3 v_color;
out vec4 f_color;
void main() { f_color = vec4(v_color, 1.0); }
"""

# The far ridge: hills around the horizon, so sky and snow meet on a line one can read.
# in_ridge: unit direction xz, height in metres, shade (0 forest band, 1 snowy crest).
RIDGE_VS = """
uniform mat4 u_view_proj;
uniform float u_radius;
uniform float u_height;
in vec4 in_ridge;
out vec3 v_color;
void main() {
    vec3 p = vec3(u_eye.x + in_ridge.x * u_radius, u_height + in_ridge.z, u_eye.z + in_ridge.y * u_radius);
    const vec3 forest = vec3(0.012, 0.03, 0.035);
    vec3 albedo = mix(forest, vec3(0.62, 0.68, 0.80), in_ridge.w);
    vec3 c = albedo * (u_sky_lin * u_ambient + u_sun_color * 0.45);
    v_color = finish(mix(c, u_horizon_lin * SKY_GAIN, 0.22 + 0.3 * in_ridge.w));
    gl_Position = u_view_proj * vec4(p, 1.0);
}
"""

# The sun's disc and glow: a small square facing the eye, on the sky only.
SUN_VS = """
uniform mat4 u_view_proj;
uniform float u_sun_size;       // half side of the square in radians
in vec2 in_corner;              // -1..1
out vec2 v_uv;
void main() {
    vec3 f = u_sun_dir;
    vec3 r = normalize(cross(f, abs(f.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0)));
    vec3 u = cross(r, f);
    vec3 d = f + (r * in_corner.x + u * in_corner.y) * u_sun_size;
    v_uv = in_corner;
    gl_Position = (u_view_proj * vec4(d, 0.0)).xyww;
}
"""

SUN_FS = """
in vec2 v_uv;
out vec4 f_color;
void main() {
    float d2 = dot(v_uv, v_uv);
    float a = exp2(-d2 * 9.0) * 0.8 + (d2 < 0.015 ? 1.0 : 0.0);
    if (a < 0.01) discard;
    f_color = vec4(finish(u_sun_color * 1.6), min(a, 1.0));
}
"""

# A rectangle on the ground (x0, z0, width, depth): the ground shadow and the track decals.
DECAL_VS = """
uniform mat4 u_view_proj;
uniform vec4 u_rect;
uniform float u_height;
in vec2 in_corner;              // 0..1
out vec3 v_pos;
out vec2 v_uv;
void main() {
    v_uv = in_corner;
    v_pos = vec3(u_rect.x + in_corner.x * u_rect.z, u_height, u_rect.y + in_corner.y * u_rect.w);
    gl_Position = u_view_proj * vec4(v_pos, 1.0);
}
"""

# The shadow takes away the sun's share of the snow's light, per channel (the blue sky light stays, so
# shadows on snow are blue, not grey): u_shadow_take, that share times the shadow's strength, is the
# same for every pixel and set once per frame (shadow_take in engine.render.environment): computed
# here, its division per channel cost a quarter of the decal on llvmpipe, which does not hoist
# uniform-only arithmetic out of the pixel loop. The fog then keeps 1 / (1 + d·density) of the
# darkening: mix(1 - m·take, 1, fog_amount(d)) with fog_amount(d) = f / (1 + f), in one division.
SHADOW_DECAL_FS = """
uniform sampler2D u_ground_mask;
uniform vec3 u_shadow_take;
in vec3 v_pos;
in vec2 v_uv;
out vec4 f_color;
void main() {
    float m = texture(u_ground_mask, v_uv).r;
    if (m < 0.004) discard;
    vec3 keep = 1.0 - m * u_shadow_take / (1.0 + length(u_eye - v_pos) * u_fog_density);
    f_color = vec4(0.5 * sqrt(keep), 1.0);   // sqrt: the picture is gamma 2
}
"""

# The snow track: its shade per texel, made on the CPU (:func:`engine.render.environment.groove_shade`:
# a groove whose walls face towards or away from the sun) in rgb as half the factor it keeps,
# how much snow the cell lost in alpha; bilinear, so its edges are soft. One fetch a pixel: the
# slope from four more fetches here cost 2.7 ms of llvmpipe time over a field of tracks.
MARKS_FS = """
uniform sampler2D u_marks;
uniform vec4 u_uv_rect;         // the decal's rectangle in the texture: u0, v0, width, depth
in vec3 v_pos;
in vec2 v_uv;
out vec4 f_color;
void main() {
    vec4 t = texture(u_marks, u_uv_rect.xy + v_uv * u_uv_rect.zw);
    if (t.a < 0.01) discard;
    vec3 k = mix(2.0 * t.rgb, vec3(1.0), fog_amount(length(u_eye - v_pos)));
    f_color = vec4(0.5 * k, 1.0);
}
"""

# Footprints: per instance centre xz, heading (cos, sin), half length, half width, strength.
PRINT_VS = """
uniform mat4 u_view_proj;
uniform float u_height;
in vec2 in_corner;              // -1..1
in vec2 i_xz;
in vec2 i_dir;
in vec2 i_half;
in float i_strength;
out vec3 v_pos;
out vec2 v_local;
out float v_strength;
out vec2 v_dir;
void main() {
    vec2 side = vec2(-i_dir.y, i_dir.x);
    vec2 xz = i_xz + i_dir * (in_corner.x * i_half.x) + side * (in_corner.y * i_half.y);
    v_pos = vec3(xz.x, u_height, xz.y);
    v_local = in_corner;
    v_strength = i_strength;
    v_dir = i_dir;
    gl_Position = u_view_proj * vec4(v_pos, 1.0);
}
"""

PRINT_FS = """
in vec3 v_pos;
in vec2 v_local;
in float v_strength;
in vec2 v_dir;
out vec4 f_color;
void main() {
    // A sole: the ball of the foot and the heel, two ellipses along the foot.
    vec2 ball = (v_local - vec2(0.38, 0.0)) / vec2(0.58, 0.95);
    vec2 heel = (v_local - vec2(-0.55, 0.0)) / vec2(0.42, 0.72);
    float f = max(1.0 - dot(ball, ball), 1.0 - dot(heel, heel));
    if (f <= 0.0) discard;
    float m = smoothstep(0.0, 0.45, f);
    // The wall facing the sun is lit, the other in shade: the slope of f, turned to the world.
    vec2 g = dot(ball, ball) < dot(heel, heel) ? -ball / vec2(0.58, 0.95) : -heel / vec2(0.42, 0.72);
    vec2 gw = v_dir * g.x + vec2(-v_dir.y, v_dir.x) * g.y;
    float wall = m * (1.0 - m) * 4.0;
    float k = 1.0 - 0.12 * m + 0.25 * wall * dot(normalize(gw + 1e-5), normalize(u_sun_dir.xz + 1e-5));
    k = mix(1.0, k, v_strength * (1.0 - fog_amount(length(u_eye - v_pos))));
    f_color = vec4(vec3(0.5 * k) * vec3(0.97, 0.985, 1.0), 1.0);
}
"""
