"""GLSL 3.30 core sources: the background photo, the sky over a photo, the ground shadow mask.

The ground and the sky without a photo are per-vertex: :mod:`engine.render.shaders_ground`.

The fragment stages here are compiled after :data:`engine.render.shaders.LIGHTING`
(and :data:`BACKGROUND` where a photo may show), whose helpers they use.
"""

from __future__ import annotations

__all__ = ["PHOTO_DEFINE", "BACKGROUND", "MASK_FS", "FULLSCREEN_VS", "SKY_VS", "SKY_FS"]

# Background photo helpers: sample the photo "cover"-fitted to the viewport. The ground
# and sky blend it in only where compiled with ``#define PHOTO`` (see PHOTO_DEFINE):
# llvmpipe runs both sides of a branch under a lane mask, so a runtime "no photo" test
# would still cost every pixel the photo fetch (3.3 ms of a 14 ms ground pass).
PHOTO_DEFINE = "#define PHOTO 1\n"
BACKGROUND = """
uniform sampler2D u_background;
uniform float u_fade;            // 1 = world only, 0 = photo only
uniform vec2 u_viewport;
uniform vec2 u_bg_scale;         // uv scale that crops the photo to the viewport aspect
vec3 photo_linear() {
    vec2 uv = gl_FragCoord.xy / u_viewport;
    uv = (uv - 0.5) * u_bg_scale + 0.5;
    return to_linear(texture(u_background, vec2(uv.x, 1.0 - uv.y)).rgb);
}
"""

# Ground shadow mask: each mask texel is a point on the ground under the casters, lit
# where four hardware 2x2 PCF taps of the sun's depth map on a disc of the penumbra's
# radius see no caster. The ground then reads its soft shadow with one bilinear fetch,
# far cheaper on llvmpipe than a PCF kernel per ground pixel. (Drawing the casters a
# second time, squashed onto the ground, cost twice as much: their vertices again; and a
# separable blur of the mask cost more than the taps.)
MASK_FS = """
uniform sampler2DShadow u_shadow_map;
uniform mat4 u_light_vp;
uniform vec4 u_rect;            // x0, z0, width, depth of the mask on the ground
uniform float u_height;
uniform float u_depth_bias;
uniform float u_spread;         // penumbra radius in shadow-map uv
in vec2 v_uv;
out float f_mask;
const vec2 DISC[4] = vec2[](vec2(-0.94, -0.40), vec2(0.95, 0.40), vec2(-0.40, 0.91), vec2(0.40, -0.91));
void main() {
    vec2 xz = u_rect.xy + v_uv * u_rect.zw;
    vec3 l = (u_light_vp * vec4(xz.x, u_height, xz.y, 1.0)).xyz * 0.5 + 0.5;
    float lit = 0.0;
    for (int i = 0; i < 4; i++) {
        lit += texture(u_shadow_map, vec3(l.xy + DISC[i] * u_spread, l.z - u_depth_bias));
    }
    bool inside = all(greaterThan(l.xy, vec2(0.0))) && all(lessThan(l, vec3(1.0)));
    f_mask = inside ? 1.0 - 0.25 * lit : 0.0;
}
"""

# A full-screen triangle (no vertex buffer) with uv over the target.
FULLSCREEN_VS = """
out vec2 v_uv;
void main() {
    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2) * 2.0 - 1.0;
    v_uv = p * 0.5 + 0.5;
    gl_Position = vec4(p, 0.0, 1.0);
}
"""

SKY_VS = """
uniform mat4 u_inv_view_proj;
noperspective out vec4 v_far;   // homogeneous far-plane point: linear in screen space, exact
void main() {
    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2) * 2.0 - 1.0;
    v_far = u_inv_view_proj * vec4(p, 1.0, 1.0);
    gl_Position = vec4(p, 0.99999, 1.0);
}
"""

SKY_FS = """
noperspective in vec4 v_far;
out vec4 f_color;
void main() {
    vec3 dir = normalize(v_far.xyz / v_far.w - u_eye);
    float t = clamp(dir.y, 0.0, 1.0);
    vec3 c = mix(u_horizon_lin, u_sky_lin, sqrt(t)) * SKY_GAIN;
    float s = max(dot(dir, u_sun_dir), 0.0);
    c += u_sun_color * (exp2(900.0 * 1.4427 * (s - 1.0)) * 4.0 + exp2(12.0 * 1.4427 * (s - 1.0)) * 0.08);
    if (dir.y < 0.0) c = u_horizon_lin * SKY_GAIN;
#ifdef PHOTO
    c = mix(photo_linear(), c, u_fade);
#endif
    f_color = vec4(finish(c), 1.0);
}
"""
