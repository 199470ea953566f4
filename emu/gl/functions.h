// The OpenGL entry points the GL backend calls, as one table of function pointers loaded through
// a context's getProcAddress. Nothing links libGL or libOpenGL: OSMesa hands out its own entry
// points (OSMesaGetProcAddress) and EGL its vendor's (eglGetProcAddress, which returns core GL
// functions too: EGL 1.5 / EGL_KHR_get_all_proc_addresses), so one binary drives both kinds and
// no gl* symbol is resolved by the dynamic linker (libOSMesa and GLVND's libOpenGL both export
// them; linking both would bind every call to whichever library came first).
#pragma once

#include <GL/glcorearb.h>

#include <string>

namespace emu::gl {

using GlProc = void (*)();

// X(type, member, "glName"): one row per entry point. Add a row here to use a new function.
#define EMU_GL_FUNCTIONS(X)                                                                   \
    X(PFNGLGETSTRINGPROC, GetString, "glGetString")                                           \
    X(PFNGLGETINTEGERVPROC, GetIntegerv, "glGetIntegerv")                                     \
    X(PFNGLGETERRORPROC, GetError, "glGetError")                                              \
    X(PFNGLFINISHPROC, Finish, "glFinish")                                                    \
    X(PFNGLVIEWPORTPROC, Viewport, "glViewport")                                              \
    X(PFNGLCLEARCOLORPROC, ClearColor, "glClearColor")                                        \
    X(PFNGLCLEARPROC, Clear, "glClear")                                                       \
    X(PFNGLPIXELSTOREIPROC, PixelStorei, "glPixelStorei")                                     \
    X(PFNGLREADPIXELSPROC, ReadPixels, "glReadPixels")                                        \
    X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers, "glGenFramebuffers")                         \
    X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers, "glDeleteFramebuffers")                \
    X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer, "glBindFramebuffer")                         \
    X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus, "glCheckFramebufferStatus")    \
    X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer, "glFramebufferRenderbuffer") \
    X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers, "glGenRenderbuffers")                      \
    X(PFNGLDELETERENDERBUFFERSPROC, DeleteRenderbuffers, "glDeleteRenderbuffers")             \
    X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer, "glBindRenderbuffer")                      \
    X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage, "glRenderbufferStorage")

// Called as gl.Clear(GL_COLOR_BUFFER_BIT): the GL name without its "gl".
struct GlFunctions {
#define EMU_GL_MEMBER(type, member, name) type member = nullptr;
    EMU_GL_FUNCTIONS(EMU_GL_MEMBER)
#undef EMU_GL_MEMBER
};

// Fills `gl` through `getProc`; false (with the first missing name in `missing`) if any is null.
template <typename GetProc>
bool loadGlFunctions(GlFunctions& gl, GetProc&& getProc, std::string& missing) {
#define EMU_GL_LOAD(type, member, name)                \
    gl.member = reinterpret_cast<type>(getProc(name)); \
    if (!gl.member) {                                  \
        missing = name;                                \
        return false;                                  \
    }
    EMU_GL_FUNCTIONS(EMU_GL_LOAD)
#undef EMU_GL_LOAD
    return true;
}

}  // namespace emu::gl
