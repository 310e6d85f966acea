#version 330 core
// Seed 002's fragment shader (../shared/seeds/002: "Volume Rendering ray-casting", Front-to-Back), with
// its quirks; where the seed is silent it takes the choice volref's glsl-basic profile documents
// (docs/conventions.md section 9, "glsl-basic and seed 002"). The SEED_NO_CUTOFF, SEED_NO_TERMINATION and
// SEED_TF_COLOUR macros (glsl_raycaster --define) leave one quirk out, for the tests that show the
// comparison sees it. Positions are the seed's texture
// coordinates: the cube [0, 1]^3 is the volume's domain (first to last voxel centre).
//
//   1) dir = normalize(front - cameraPos); acc = 0
//   2) for i < steps (steps = int(depth * 1.732)):
//        textureValue = texture(volume, pos); density = textureValue.r
//        if density >= 0.01: curr = K * tf(density);       (cutoff, intensity K)
//                            acc += (1 - acc.a) * curr.a * textureValue.rrra   (shaded: rrr lit by Phong)
//        pos += dir * step
//        stop if any pos outside [0, 1], or acc.a > 1
//   3) frag_color = acc
uniform sampler3D volume;      // GL_R32F, GL_LINEAR, GL_CLAMP_TO_EDGE: the scalar values as stored
uniform vec3 u_dims;            // n per axis: the cube's [0, 1] runs from texel centre 0 to texel centre n - 1
uniform vec3 u_lo, u_extent;    // the domain in world units
uniform float u_step;           // the world step h (render.step in world units)
uniform float u_depth;          // the largest extent over h: the seed's depth_
uniform float u_K;              // the intensity K (render.profile_options.intensity)
uniform int u_nopacity;         // the opacity rows (value, a), piecewise linear, clamped to the end rows
uniform vec2 u_opacity[64];
// the camera (volref's Camera::ray): pixel (x, y) from the top, through its centre
uniform int u_ortho;
uniform vec3 u_eye, u_forward, u_right, u_up;
uniform float u_tan_half_fov, u_aspect, u_half_height;
uniform vec2 u_size;
// shading (transfer/Shader.h's formulas)
uniform int u_shaded, u_model, u_two_sided;   // model 0 blinn-phong, 1 phong, 2 nodal
uniform float u_ka, u_kd, u_ks, u_n, u_kc, u_kl, u_zero_gradient;
uniform int u_nlights;
uniform int u_light_type[4];     // 0 headlight, 1 directional
uniform vec3 u_light_dir[4], u_light_color[4];

out vec4 frag_color;

float tf_opacity(float v) {
    if (v <= u_opacity[0].x) return u_opacity[0].y;
    for (int j = 1; j < u_nopacity; ++j) {
        if (v <= u_opacity[j].x) {
            vec2 a = u_opacity[j - 1], b = u_opacity[j];
            if (b.x == a.x) return b.y;
            return a.y + (v - a.x) / (b.x - a.x) * (b.y - a.y);
        }
    }
    return u_opacity[u_nopacity - 1].y;
}

// The cube's [0, 1] is the domain between the first and last voxel centres: texel i + 0.5 of n.
vec4 fetch(vec3 p) { return texture(volume, (p * (u_dims - 1.0) + 0.5) / u_dims); }

// getNormalFromVol: +-e = 1/10 in the cube's coordinates; the differences divided by the world offset
// (2 e extent) so that the lighting is in world space (the seed lights in a space it does not name).
vec3 gradientFromVol(vec3 point) {
    float e = 1.0 / 10.0;
    vec3 d = vec3(fetch(point + vec3(e, 0, 0)).r - fetch(point - vec3(e, 0, 0)).r,
                  fetch(point + vec3(0, e, 0)).r - fetch(point - vec3(0, e, 0)).r,
                  fetch(point + vec3(0, 0, e)).r - fetch(point - vec3(0, 0, e)).r);
    return d / (2.0 * e * u_extent);
}

float clamp_dot(float x) { return u_two_sided != 0 ? abs(x) : max(x, 0.0); }

vec3 phong(vec3 m, vec3 point, vec3 V, float depth) {
    vec3 g = gradientFromVol(point);
    float gl = length(g);
    if (!(gl > u_zero_gradient)) return m;
    vec3 N = g / gl;  // the seed's normal: normalize(+grad f)
    vec3 c = vec3(0.0);
    for (int l = 0; l < u_nlights; ++l) {
        vec3 L = u_light_type[l] == 0 ? V : u_light_dir[l];
        float ndl = clamp_dot(dot(N, L));
        float sd;
        if (u_model == 1) {
            vec3 R = 2.0 * dot(N, L) * N - L;
            sd = max(dot(R, V), 0.0);
        } else {
            sd = clamp_dot(dot(N, normalize(L + V)));
        }
        float cue = 1.0 / (u_kc + u_kl * depth);
        vec3 I = u_light_color[l];
        c += I * (u_ka * m) + I * (u_kd * m * ndl * cue);
        if (u_ks != 0.0) c += I * (u_ks * pow(sd, u_n) * cue);
    }
    return c;
}

void main() {
    // volref's pixel (x, y), y downwards: GL's window row r is image row H - 1 - r.
    float fx = gl_FragCoord.x, fy = u_size.y - gl_FragCoord.y;
    float nx = 2.0 * fx / u_size.x - 1.0, ny = 1.0 - 2.0 * fy / u_size.y;
    vec3 origin, wdir;
    if (u_ortho != 0) {
        origin = u_eye + (nx * u_half_height * u_aspect) * u_right + (ny * u_half_height) * u_up;
        wdir = u_forward;
    } else {
        origin = u_eye;
        wdir = normalize(u_forward + (nx * u_tan_half_fov * u_aspect) * u_right + (ny * u_tan_half_fov) * u_up);
    }
    // The cube's front face: where the pixel's ray enters [0, 1]^3 (the seed rasterises the cube and
    // reads it from the interpolated texture coordinates).
    vec3 camPos = (origin - u_lo) / u_extent;
    vec3 rd = wdir / u_extent;
    vec3 inv = 1.0 / rd;
    vec3 t0 = (vec3(0.0) - camPos) * inv, t1 = (vec3(1.0) - camPos) * inv;
    vec3 tmin = min(t0, t1), tmax = max(t0, t1);
    float tin = max(max(tmin.x, tmin.y), max(tmin.z, 0.0));
    float tout = min(min(tmax.x, tmax.y), tmax.z);
    vec4 acc = vec4(0.0);
    if (!(tin <= tout)) { frag_color = acc; return; }
    vec3 front = camPos + tin * rd;
    // 1) the normalized direction between the camera and the front (cube coordinates); a step of h
    //    world units along it.
    vec3 dir = u_ortho != 0 ? normalize(rd) : normalize(front - camPos);
    float step = u_step / length(dir * u_extent);
    vec3 V = -wdir;
    int steps = int(u_depth * 1.732);
    vec3 pos = front;
    for (int i = 0; i < steps; ++i) {
        vec4 textureValue = fetch(pos);
        float density = textureValue.r;
#ifndef SEED_NO_CUTOFF
        if (density >= 0.01) {
#else
        {
#endif
            float curr_a = u_K * clamp(tf_opacity(density), 0.0, 1.0);
#ifndef SEED_TF_COLOUR
            vec4 col = textureValue.rrra;
#else
            vec4 col = vec4(1.0);  // the scenes' colour map is white: the transfer function's colour
#endif
            if (u_shaded != 0) {
                vec3 wpos = u_lo + pos * u_extent;
                col.rgb = phong(col.rgb, pos, V, dot(wpos - origin, wdir));
            }
            acc += (1.0 - acc.a) * curr_a * col;
        }
        pos += dir * step;
        if (any(lessThan(pos, vec3(0.0))) || any(greaterThan(pos, vec3(1.0)))) break;
#ifndef SEED_NO_TERMINATION
        if (acc.a > 1.0) break;
#endif
    }
    frag_color = acc;
}
