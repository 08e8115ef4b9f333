"""GLSL 3.30 core sources: shared lighting, the solids, lines, points and text.

The environment (ground, sky, shadow mask) lives in :mod:`engine.render.shaders_env`.

Colour pipeline: inputs are sRGB, converted to linear for lighting, then an exponential
tone curve and gamma on output ("gamma-correct-ish": gamma 2.0, i.e. a square and a
square root, because on llvmpipe every ``pow`` is an exp/log pair per pixel; and no
extra HDR target, which would cost bandwidth). Lighting is one sun with soft shadows, a
hemisphere ambient (blue sky above, bright snow bounce below) and a little rim light,
which together give the soft daylight look of a snowy scene.

Frame cost on llvmpipe is almost all fragment shading, so the shaders avoid ``pow``,
per-pixel procedural noise (:mod:`engine.render.noise` bakes it) and wide PCF kernels on
the ground (:mod:`engine.render.shadows`).
"""

from __future__ import annotations

__all__ = [
    "HEADER",
    "LIGHTING",
    "CAPSULE_VS",
    "CONE_VS",
    "BOX_VS",
    "LIT_FS",
    "FLAT_FS",
    "DEPTH_FS",
    "LINE_VS",
    "LINE_FS",
    "POINT_VS",
    "POINT_FS",
    "TEXT_VS",
    "TEXT_FS",
    "OVERLAY_VS",
    "OVERLAY_FS",
]

HEADER = "#version 330 core\n"

# Shared lighting, shadow and colour helpers (fragment stage).
LIGHTING = """
uniform vec3 u_eye;
uniform vec3 u_sun_dir;         // unit, towards the sun
uniform vec3 u_sun_color;
uniform vec3 u_sky_lin;
uniform vec3 u_horizon_lin;
uniform float u_ambient;
uniform mat4 u_light_vp;
uniform sampler2DShadow u_shadow_map;
uniform float u_shadows_on;
uniform float u_shadow_texel;
uniform float u_softness;
uniform float u_normal_bias;
uniform float u_depth_bias;
uniform float u_fog_density;
const float SKY_GAIN = 1.2;            // the sky is a light source: brighter than lit albedo
float fog_amount(float d) { float f = d * u_fog_density; return f / (1.0 + f); }

vec3 to_linear(vec3 c) { return c * c; }

vec3 finish(vec3 c) {
    // Tone curve ~ 1 - exp(-1.5c) (a rational fit, cheaper than three exp), then gamma.
    vec3 y = 1.5 * max(c, 0.0);
    return sqrt(y * (1.0 + 0.5 * y) / (1.0 + y + 0.5 * y * y));
}

// Objects: four taps of hardware 2x2 PCF on a small disc. Objects cover few pixels, so
// the kernel is affordable there; the ground uses the cheaper blurred mask instead.
const vec2 POISSON[4] = vec2[](vec2(-0.94, -0.40), vec2(0.95, 0.40), vec2(-0.40, 0.91), vec2(0.40, -0.91));

float shadow_factor(vec3 p, vec3 n) {
    if (u_shadows_on < 0.5) return 1.0;
    // Normal offset grows as the surface turns from the sun (slope-scaled): there the
    // PCF taps reach furthest across the curved surface towards its sunlit side.
    float turned = 1.0 - clamp(dot(n, u_sun_dir), 0.0, 1.0);
    vec4 ls = u_light_vp * vec4(p + n * (u_normal_bias * (1.0 + 2.0 * turned)), 1.0);
    vec3 uvz = ls.xyz / ls.w * 0.5 + 0.5;
    if (uvz.x <= 0.0 || uvz.y <= 0.0 || uvz.x >= 1.0 || uvz.y >= 1.0 || uvz.z >= 1.0) return 1.0;
    vec2 scale = vec2(u_softness * u_shadow_texel);
    float sum = 0.0;
    for (int i = 0; i < 4; i++) {
        sum += texture(u_shadow_map, vec3(uvz.xy + POISSON[i] * scale, uvz.z - u_depth_bias));
    }
    return sum * 0.25;
}

vec3 ambient_light(vec3 n) {
    const vec3 bounce = vec3(0.64, 0.67, 0.74);   // snow bounce light, linear
    return mix(bounce, u_sky_lin, clamp(n.y * 0.5 + 0.5, 0.0, 1.0)) * u_ambient;
}

vec3 shade(vec3 albedo, vec3 n, vec3 p, float sh, float shininess, float spec_amount) {
    vec3 L = u_sun_dir;
    vec3 V = normalize(u_eye - p);
    float ndl = max(dot(n, L), 0.0);
    vec3 H = normalize(L + V);
    float spec = exp2(shininess * (max(dot(n, H), 1e-4) - 1.0) * 1.4427) * spec_amount * ndl;
    float fr = 1.0 - max(dot(n, V), 0.0);
    float rim = fr * fr * fr * 0.18;
    vec3 c = albedo * (ambient_light(n) + u_sun_color * ndl * sh) + u_sun_color * spec * sh;
    return c + rim * u_sky_lin;
}

"""

CAPSULE_VS = """
uniform mat4 u_view_proj;
uniform vec3 u_cam;
uniform float u_inflate_px;     // > 0 only in the outline pass
uniform float u_px_scale;       // world size of one pixel at distance 1
in vec4 in_vert;                // unit direction xyz, end flag w
in vec3 i_a;
in vec3 i_b;
in float i_r;
in vec3 i_color;
in float i_outline;
out vec3 v_pos;
out vec3 v_normal;
out vec3 v_color;
out float v_fog;
uniform float u_fog_density;
void main() {
    vec3 axis = i_b - i_a;
    float len = length(axis);
    vec3 y = len > 1e-6 ? axis / len : vec3(0.0, 1.0, 0.0);
    vec3 helper = abs(y.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 x = normalize(cross(helper, y));
    vec3 z = cross(x, y);
    vec3 n = x * in_vert.x + y * in_vert.y + z * in_vert.z;
    vec3 c = mix(i_a, i_b, in_vert.w);
    float r = i_r;
    if (u_inflate_px > 0.0) {
        if (i_outline < 0.5) { gl_Position = vec4(0.0, 0.0, 2.0, 1.0); return; }
        r += u_inflate_px * u_px_scale * length(c - u_cam);
    }
    v_pos = c + n * r;
    v_normal = n;
    v_color = i_color;
    float fog = length(v_pos - u_cam) * u_fog_density;
    v_fog = fog / (1.0 + fog);
    gl_Position = u_view_proj * vec4(v_pos, 1.0);
}
"""

# Cones (conifer tiers): base centre i_a, apex i_b, base radius i_r; i_outline is the
# snow on the tier (0..1), which whitens its upper side in a ragged band.
CONE_VS = """
uniform mat4 u_view_proj;
uniform vec3 u_cam;
uniform float u_fog_density;
in vec4 in_vert;                // cos, sin round the axis; height fraction; 1 on the base disc
in vec3 i_a;
in vec3 i_b;
in float i_r;
in vec3 i_color;
in float i_outline;
out vec3 v_pos;
out vec3 v_normal;
out vec3 v_color;
out float v_fog;
void main() {
    vec3 axis = i_b - i_a;
    float h = max(length(axis), 1e-6);
    vec3 y = axis / h;
    vec3 helper = abs(y.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 x = normalize(cross(helper, y));
    vec3 z = cross(x, y);
    vec2 cs = in_vert.xy;
    float t = in_vert.z;
    float seed = dot(i_a, vec3(12.9, 0.0, 78.2));
    float angle = atan(cs.y, cs.x);
    // A ragged skirt: every other spoke of the rim hangs lower and reaches further.
    float spike = in_vert.w < 0.5 && t < 0.01 ? 0.5 + 0.5 * cos(angle * 9.0 + seed) : 0.0;
    vec3 radial = x * cs.x + z * cs.y;
    float r = i_r * (1.0 - t) * (1.0 + 0.12 * spike);
    v_pos = i_a + axis * t + radial * r - y * (0.10 * h * spike);
    v_normal = in_vert.w > 0.5 ? -y : normalize(radial * h + y * i_r);
    float snow = i_outline * smoothstep(0.2, 0.5, t + 0.22 * sin(angle * 5.0 + seed) + 0.15 * spike);
    v_color = mix(i_color, vec3(0.93, 0.95, 0.99), snow);
    float fog = length(v_pos - u_cam) * u_fog_density;
    v_fog = fog / (1.0 + fog);
    gl_Position = u_view_proj * vec4(v_pos, 1.0);
}
"""

BOX_VS = """
uniform mat4 u_view_proj;
uniform vec3 u_cam;
uniform float u_inflate_px;
uniform float u_px_scale;
in vec3 in_pos;
in vec3 in_normal;
in vec3 i_center;
in vec3 i_half;
in vec4 i_rot;
in vec3 i_color;
in float i_outline;
out vec3 v_pos;
out vec3 v_normal;
out vec3 v_color;
out float v_fog;
uniform float u_fog_density;
vec3 qrot(vec4 q, vec3 v) {
    vec3 t = 2.0 * cross(q.yzw, v);
    return v + q.x * t + cross(q.yzw, t);
}
void main() {
    vec3 half_ext = i_half;
    if (u_inflate_px > 0.0) {
        if (i_outline < 0.5) { gl_Position = vec4(0.0, 0.0, 2.0, 1.0); return; }
        half_ext += vec3(u_inflate_px * u_px_scale * length(i_center - u_cam));
    }
    v_pos = i_center + qrot(i_rot, in_pos * half_ext);
    v_normal = qrot(i_rot, in_normal);
    v_color = i_color;
    float fog = length(v_pos - u_cam) * u_fog_density;
    v_fog = fog / (1.0 + fog);
    gl_Position = u_view_proj * vec4(v_pos, 1.0);
}
"""

LIT_FS = """
in vec3 v_pos;
in vec3 v_normal;
in vec3 v_color;
in float v_fog;                 // fog amount, per vertex: objects are small, fog varies slowly
out vec4 f_color;
void main() {
    vec3 n = normalize(v_normal);
    float sh = shadow_factor(v_pos, n);
    vec3 c = shade(to_linear(v_color), n, v_pos, sh, 28.0, 0.25);
    f_color = vec4(finish(mix(c, u_horizon_lin * SKY_GAIN, v_fog)), 1.0);
}
"""

FLAT_FS = """
uniform vec3 u_color;
in vec3 v_pos;
out vec4 f_color;
void main() { f_color = vec4(u_color, 1.0); }
"""

DEPTH_FS = """
out vec4 f_color;
void main() { f_color = vec4(1.0); }
"""

LINE_VS = """
uniform mat4 u_view_proj;
uniform vec2 u_viewport;
in vec2 in_corner;              // x: 0 at p0, 1 at p1; y: -1/+1 side
in vec3 i_p0;
in vec3 i_p1;
in vec3 i_color;
in float i_width;
out vec3 v_color;
void main() {
    vec4 c0 = u_view_proj * vec4(i_p0, 1.0);
    vec4 c1 = u_view_proj * vec4(i_p1, 1.0);
    const float EPS = 1e-3;
    if (c0.w < EPS && c1.w < EPS) { gl_Position = vec4(0.0, 0.0, 2.0, 1.0); return; }
    if (c0.w < EPS) c0 = mix(c0, c1, (EPS - c0.w) / (c1.w - c0.w));
    if (c1.w < EPS) c1 = mix(c1, c0, (EPS - c1.w) / (c0.w - c1.w));
    vec2 s0 = c0.xy / c0.w * u_viewport * 0.5;
    vec2 s1 = c1.xy / c1.w * u_viewport * 0.5;
    vec2 d = s1 - s0;
    d = length(d) > 1e-6 ? normalize(d) : vec2(1.0, 0.0);
    vec2 side = vec2(-d.y, d.x);
    vec4 c = mix(c0, c1, in_corner.x);
    vec2 off = (side * in_corner.y + d * (in_corner.x * 2.0 - 1.0)) * i_width * 0.5;
    c.xy += off / (u_viewport * 0.5) * c.w;
    v_color = i_color;
    gl_Position = c;
}
"""

LINE_FS = """
in vec3 v_color;
out vec4 f_color;
void main() { f_color = vec4(v_color, 1.0); }
"""

POINT_VS = """
uniform mat4 u_view_proj;
uniform float u_px_per_unit;    // pixels per metre at distance 1
in vec3 i_pos;
in float i_size;
in vec3 i_color;
in float i_pixels;
out vec3 v_color;
void main() {
    gl_Position = u_view_proj * vec4(i_pos, 1.0);
    float px = i_pixels > 0.5 ? i_size : i_size * u_px_per_unit / max(gl_Position.w, 1e-3);
    gl_PointSize = clamp(px, 1.0, 128.0);
    v_color = i_color;
}
"""

POINT_FS = """
in vec3 v_color;
out vec4 f_color;
void main() {
    float d = length(gl_PointCoord * 2.0 - 1.0);
    float a = 1.0 - smoothstep(0.6, 1.0, d);
    if (a < 0.02) discard;
    f_color = vec4(v_color * (1.05 - 0.15 * d), a);
}
"""

TEXT_VS = """
uniform vec4 u_rect;            // x, y, w, h in pixels, top-left origin
uniform vec2 u_viewport;
in vec2 in_corner;              // 0..1
out vec2 v_uv;
void main() {
    vec2 p = u_rect.xy + in_corner * u_rect.zw;
    gl_Position = vec4(p.x / u_viewport.x * 2.0 - 1.0, 1.0 - p.y / u_viewport.y * 2.0, 0.0, 1.0);
    v_uv = in_corner;
}
"""

TEXT_FS = """
uniform sampler2D u_tex;
uniform float u_alpha;          // fades a whole line, panel included
in vec2 v_uv;
out vec4 f_color;
void main() { vec4 c = texture(u_tex, v_uv); f_color = vec4(c.rgb, c.a * u_alpha); }
"""

# Overlays: a picture over a rectangle of the background photo, placed as the photo is
# (cover-fitted to the viewport); optionally at one depth, so the 3-D scene's depth test
# decides, pixel by pixel of its alpha, what is in front.
OVERLAY_VS = """
uniform vec4 u_rect;            // u0, v0, u1, v1 on the photo, top-left origin
uniform vec2 u_bg_scale;
in vec2 in_corner;              // 0..1
out vec2 v_uv;
void main() {
    vec2 img = mix(u_rect.xy, u_rect.zw, in_corner);
    vec2 s = (vec2(img.x, 1.0 - img.y) - 0.5) / u_bg_scale + 0.5;
    gl_Position = vec4(s * 2.0 - 1.0, 0.0, 1.0);
    v_uv = in_corner;
}
"""

OVERLAY_FS = """
uniform sampler2D u_tex;
uniform float u_alpha;
uniform float u_depth;          // window depth of the picture (0 when not depth-tested)
uniform float u_photo;          // 1: tone-map like the background photo
in vec2 v_uv;
out vec4 f_color;
void main() {
    vec4 c = texture(u_tex, v_uv);
    float a = c.a * u_alpha;
    if (a < 0.004) discard;
    vec3 rgb = u_photo > 0.5 ? finish(to_linear(c.rgb)) : c.rgb;
    gl_FragDepth = u_depth;
    f_color = vec4(rgb, a);
}
"""
