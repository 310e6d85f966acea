// glsl_raycaster: seed 002's GLSL ray caster (raycast.frag) run headless through EGL on Mesa (the
// surfaceless platform: no X server, no window), on one volref scene. It renders into a GL_RGBA32F
// framebuffer and writes the premultiplied RGBA floats as EXR for `volref compare`.
//
//   glsl_raycaster SCENE.json OUT.exr [--set key=value]... [--require-renderer SUBSTRING] [--define MACRO] [--egl-device]
// (--define: a macro put after the shader's #version line; raycast.frag's SEED_NO_* variants leave one
// quirk out, for the tests that show the comparison sees it.)
//
// The scene is read with volref's own loader (load_scene, load_volume, world_step), so both renderers
// see the same volume, transfer function, camera, lights and step. What the program renders: one
// volume, a box bound (the domain), no transform, clip planes or crop, the composite projection, a
// perspective or orthographic camera, an opacity given as rows in the data domain (the colour map is not
// read: the seed composites textureValue.rrr). Anything else is an error (exit 2).
// Exit status: 0 written; 1 no GL context or a GL error (never a skip: a test that cannot get a
// context fails); 2 a scene the program does not render.
#include "tests/gpu/gl_context.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "core/film/ImageWriter.h"
#include "volref_core.h"

#ifndef VOLREF_GLSL_SHADER
#error "VOLREF_GLSL_SHADER: the path of raycast.frag"
#endif

namespace {

using gl_headless::check_gl;
using gl_headless::GlFail;

[[noreturn]] void fail(int code, const std::string& what) { gl_headless::gl_fail(code, what); }

std::string read_text(const char* path) {
    std::ifstream in(path);
    if (!in) fail(1, std::string("cannot read ") + path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

int run(int argc, char** argv) {
    std::vector<std::string> overrides;
    std::string require_renderer, defines;
    bool egl_device = false;
    std::vector<std::string> positional;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--set" && i + 1 < argc) overrides.emplace_back(argv[++i]);
        else if (a == "--require-renderer" && i + 1 < argc) require_renderer = argv[++i];
        else if (a == "--define" && i + 1 < argc) defines += std::string("#define ") + argv[++i] + "\n";
        else if (a == "--egl-device") egl_device = true;
        else positional.push_back(a);
    }
    if (positional.size() != 2) fail(2, "usage: glsl_raycaster SCENE.json OUT.exr [--set key=value]... [--require-renderer S] [--define M] [--egl-device]");
    using namespace volref;
    const Scene scene = load_scene(positional[0], overrides);
    if (scene.volumes.size() != 1) fail(2, "one volume only");
    const VolumeSpec& vs = scene.volume();
    if (vs.bounds.type != BoundsSpec::Type::Box || vs.bounds.min || vs.bounds.max) fail(2, "volume.bounds: the domain box only");
    if (vs.transform || !vs.clip_planes.empty() || vs.crop) fail(2, "no transform, clip planes or crop");
    if (vs.classification || vs.transfer.domain != TransferSpec::Domain::Data || vs.transfer.opacity.empty() ||
        !vs.transfer.gradient_opacity.empty())
        fail(2, "volume.transfer: opacity rows in the data domain, no gradient opacity");
    if (vs.transfer.opacity.size() > 64) fail(2, "at most 64 opacity rows");
    if (vs.interpolation != Interpolation::Trilinear || vs.classify != VolumeSpec::Classify::Post) fail(2, "trilinear, post-classified");
    if (scene.render.projection != Projection::Composite) fail(2, "render.projection: composite only");
    if (scene.lights.size() > 4) fail(2, "at most 4 lights");
    const CameraSpec& cam = scene.camera;
    if (cam.type != CameraSpec::Type::Perspective && cam.type != CameraSpec::Type::Orthographic)
        fail(2, "camera: perspective or orthographic");

    const Volume vol = load_volume(vs);
    const double h = world_step(scene.render, vol);
    const glm::dvec3 lo = vol.domain_min(), extent = vol.domain_max() - vol.domain_min();
    const int W = scene.image.width, H = scene.image.height;

    gl_headless::make_context("glsl_raycaster", require_renderer, egl_device);

    // The volume: GL_R32F, linear, clamped to the edge.
    std::vector<float> voxels(std::size_t(vol.dims[0] * vol.dims[1] * vol.dims[2]));
    for (std::size_t i = 0; i < voxels.size(); ++i) voxels[i] = float(vol.values[i]);
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_3D, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage3D(GL_TEXTURE_3D, 0, GL_R32F, GLsizei(vol.dims[0]), GLsizei(vol.dims[1]), GLsizei(vol.dims[2]), 0, GL_RED,
                 GL_FLOAT, voxels.data());
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    for (GLenum w : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R})
        glTexParameteri(GL_TEXTURE_3D, w, GL_CLAMP_TO_EDGE);
    check_gl("volume texture");

    // The target: GL_RGBA32F (blending, dithering, depth test and culling off).
    gl_headless::make_framebuffer(GL_RGBA32F, W, H);

    // A full-screen triangle; the fragment shader casts the pixel's ray.
    const std::string vs_src = "#version 330 core\nvoid main() {\n"
                               "  vec2 p = vec2((gl_VertexID == 1) ? 3.0 : -1.0, (gl_VertexID == 2) ? 3.0 : -1.0);\n"
                               "  gl_Position = vec4(p, 0.0, 1.0);\n}\n";
    std::string frag = read_text(VOLREF_GLSL_SHADER);
    frag.insert(frag.find('\n') + 1, defines);
    const GLuint prog = gl_headless::link_program(vs_src, frag);
    glUseProgram(prog);
    auto loc = [&](const char* name) { return glGetUniformLocation(prog, name); };
    auto v3 = [&](const char* name, const glm::dvec3& v) { glUniform3f(loc(name), float(v.x), float(v.y), float(v.z)); };
    glUniform1i(loc("volume"), 0);
    v3("u_dims", glm::dvec3(double(vol.dims[0]), double(vol.dims[1]), double(vol.dims[2])));
    v3("u_lo", lo);
    v3("u_extent", extent);
    glUniform1f(loc("u_step"), float(h));
    glUniform1f(loc("u_depth"), float(std::max({extent.x, extent.y, extent.z}) / h));
    glUniform1f(loc("u_K"), float(scene.render.profile_options.intensity));
    std::vector<float> rows;
    for (const auto& r : vs.transfer.opacity) rows.insert(rows.end(), {float(r[0]), float(r[1])});
    glUniform1i(loc("u_nopacity"), GLint(vs.transfer.opacity.size()));
    glUniform2fv(loc("u_opacity"), GLsizei(vs.transfer.opacity.size()), rows.data());
    // Camera: Camera.cpp's frame, computed in double, passed as float.
    const glm::dvec3 forward = glm::normalize(cam.target - cam.eye);
    const glm::dvec3 right = glm::normalize(glm::cross(forward, cam.up));
    const glm::dvec3 up = glm::cross(right, forward);
    glUniform1i(loc("u_ortho"), cam.type == CameraSpec::Type::Orthographic ? 1 : 0);
    v3("u_eye", cam.eye);
    v3("u_forward", forward);
    v3("u_right", right);
    v3("u_up", up);
    glUniform1f(loc("u_tan_half_fov"), float(std::tan(cam.fov_y * std::numbers::pi / 180.0 / 2.0)));
    glUniform1f(loc("u_aspect"), float(double(W) / double(H)));
    glUniform1f(loc("u_half_height"), float(cam.height / 2.0));
    glUniform2f(loc("u_size"), float(W), float(H));
    // Shading: Shader.h's coefficients and lights; the zero-gradient tolerance as PreparedVolume sets it.
    glUniform1i(loc("u_shaded"), vs.shading ? 1 : 0);
    if (vs.shading) {
        const ShadingSpec& sh = *vs.shading;
        const int model = sh.model == ShadingSpec::Model::Phong ? 1 : sh.model == ShadingSpec::Model::Nodal ? 2 : 0;
        glUniform1i(loc("u_model"), model);
        glUniform1i(loc("u_two_sided"), sh.two_sided ? 1 : 0);
        glUniform1f(loc("u_ka"), float(sh.ka));
        glUniform1f(loc("u_kd"), float(sh.kd));
        glUniform1f(loc("u_ks"), float(model == 2 ? 0.0 : sh.ks));
        glUniform1f(loc("u_n"), float(sh.n));
        glUniform1f(loc("u_kc"), float(sh.kc));
        glUniform1f(loc("u_kl"), float(sh.kl));
        const auto [vmin, vmax] = vol.value_range();
        const double voxel = std::min({vol.spacing.x, vol.spacing.y, vol.spacing.z});
        glUniform1f(loc("u_zero_gradient"),
                    float(conventions::kZeroGradientRelative * std::max(std::fabs(vmin), std::fabs(vmax)) / voxel));
        glUniform1i(loc("u_nlights"), GLint(scene.lights.size()));
        for (std::size_t l = 0; l < scene.lights.size(); ++l) {
            const std::string i = "[" + std::to_string(l) + "]";
            glUniform1i(loc(("u_light_type" + i).c_str()), scene.lights[l].type == LightSpec::Type::Headlight ? 0 : 1);
            v3(("u_light_dir" + i).c_str(), scene.lights[l].direction);
            v3(("u_light_color" + i).c_str(), scene.lights[l].color);
        }
    }
    check_gl("uniforms");
    GLuint vao = 0;
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glFinish();
    check_gl("draw");
    std::vector<float> px(std::size_t(W) * std::size_t(H) * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_FLOAT, px.data());
    check_gl("read");

    Image img(W, H, {"R", "G", "B", "A"});
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (int c = 0; c < 4; ++c) img.at(x, y, std::size_t(c)) = px[(std::size_t(H - 1 - y) * std::size_t(W) + std::size_t(x)) * 4 + std::size_t(c)];
    write_image(img, positional[1], scene.image.background);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const GlFail& f) {
        std::fprintf(stderr, "glsl_raycaster: %s\n", f.what.c_str());
        return f.code;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "glsl_raycaster: %s\n", e.what());
        return 2;
    }
}
