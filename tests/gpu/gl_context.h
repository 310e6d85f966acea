// A headless OpenGL 3.3 core context through EGL, shared by tests/gpu/glsl/glsl_raycaster and
// tests/gpu/slicing's gl_slicer and gl_probe: Mesa's surfaceless
// platform (llvmpipe; no X server, no window), or with `egl_device` the first EGL device that initialises
// (a GPU machine: NVIDIA's driver has no surfaceless platform). Errors are thrown as GlFail; code 1 is
// "no GL context or a GL error" (never a skip).
#pragma once
#include <EGL/egl.h>
#include <EGL/eglext.h>
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <cstdio>
#include <cstring>
#include <string>

namespace gl_headless {

struct GlFail {
    int code;
    std::string what;
};

[[noreturn]] inline void gl_fail(int code, const std::string& what) { throw GlFail{code, what}; }

inline void check_gl(const char* where) {
    if (const GLenum e = glGetError(); e != GL_NO_ERROR) gl_fail(1, std::string("GL error ") + std::to_string(e) + " at " + where);
}

// Makes the context current and prints GL_RENDERER / GL_VERSION on stderr; fails unless GL_RENDERER
// contains `require_renderer` (when not empty).
inline void make_context(const char* program, const std::string& require_renderer, bool egl_device) {
    auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!get_platform_display) gl_fail(1, "EGL: no eglGetPlatformDisplayEXT");
    EGLDisplay dpy = EGL_NO_DISPLAY;
    EGLint major = 0, minor = 0;
    if (egl_device) {
        auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
        EGLDeviceEXT devices[8];
        EGLint count = 0;
        if (!query_devices || !query_devices(8, devices, &count) || count < 1) gl_fail(1, "EGL: no EGL device (EGL_EXT_device_enumeration)");
        for (EGLint d = 0; d < count && dpy == EGL_NO_DISPLAY; ++d) {
            dpy = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[d], nullptr);
            if (dpy != EGL_NO_DISPLAY && !eglInitialize(dpy, &major, &minor)) dpy = EGL_NO_DISPLAY;
        }
        if (dpy == EGL_NO_DISPLAY) gl_fail(1, "EGL: no EGL device initialises");
    } else {
        dpy = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        if (dpy == EGL_NO_DISPLAY) gl_fail(1, "EGL: no surfaceless display (is libegl-mesa0 installed?)");
        if (!eglInitialize(dpy, &major, &minor)) gl_fail(1, "EGL: eglInitialize failed");
    }
    if (!eglBindAPI(EGL_OPENGL_API)) gl_fail(1, "EGL: no OpenGL API");
    // Mesa's surfaceless platform may offer no config for OpenGL: then EGL_KHR_no_config_context.
    const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config = EGL_NO_CONFIG_KHR;
    EGLint n = 0;
    if (!eglChooseConfig(dpy, config_attribs, &config, 1, &n) || n < 1) config = EGL_NO_CONFIG_KHR;
    const EGLint ctx_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                                  EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext ctx = eglCreateContext(dpy, config, EGL_NO_CONTEXT, ctx_attribs);
    if (ctx == EGL_NO_CONTEXT) gl_fail(1, "EGL: cannot create an OpenGL 3.3 core context");
    if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) gl_fail(1, "EGL: eglMakeCurrent without a surface failed");
    const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    std::fprintf(stderr, "%s: GL_RENDERER %s, GL_VERSION %s\n", program, renderer ? renderer : "?", version ? version : "?");
    if (!require_renderer.empty() && (!renderer || !std::strstr(renderer, require_renderer.c_str())))
        gl_fail(1, "GL_RENDERER is not " + require_renderer + " (the test's tolerance is derived for it)");
}

inline GLuint compile_shader(GLenum type, const std::string& src) {
    const GLuint s = glCreateShader(type);
    const char* p = src.c_str();
    glShaderSource(s, 1, &p, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[4096];
        glGetShaderInfoLog(s, sizeof log, nullptr, log);
        gl_fail(1, std::string("shader compile: ") + log + "\n" + src);
    }
    return s;
}

inline GLuint link_program(const std::string& vertex, const std::string& fragment) {
    const GLuint prog = glCreateProgram();
    glAttachShader(prog, compile_shader(GL_VERTEX_SHADER, vertex));
    glAttachShader(prog, compile_shader(GL_FRAGMENT_SHADER, fragment));
    glLinkProgram(prog);
    GLint linked = 0;
    glGetProgramiv(prog, GL_LINK_STATUS, &linked);
    if (!linked) {
        char log[4096];
        glGetProgramInfoLog(prog, sizeof log, nullptr, log);
        gl_fail(1, std::string("program link: ") + log);
    }
    return prog;
}

// A W x H frame buffer object with one colour renderbuffer of `internal_format`, bound, viewport set,
// blending and dithering off.
inline GLuint make_framebuffer(GLenum internal_format, int W, int H) {
    GLuint fbo = 0, rb = 0;
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glGenRenderbuffers(1, &rb);
    glBindRenderbuffer(GL_RENDERBUFFER, rb);
    glRenderbufferStorage(GL_RENDERBUFFER, internal_format, W, H);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) gl_fail(1, "GL: framebuffer incomplete");
    glViewport(0, 0, W, H);
    glDisable(GL_BLEND);
    glDisable(GL_DITHER);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    check_gl("framebuffer");
    return fbo;
}

}  // namespace gl_headless
