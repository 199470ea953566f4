// The OpenGL entry points the GL backend calls, as one table of function pointers loaded through
// a context's getProcAddress. Nothing links libGL or libOpenGL: OSMesa hands out its own entry
// points (OSMesaGetProcAddress) and EGL its vendor's (eglGetProcAddress, which returns core GL
// functions too: EGL 1.5 / EGL_KHR_get_all_proc_addresses), so one binary drives both kinds and
// no gl* symbol is resolved by the dynamic linker (libOSMesa and GLVND's libOpenGL both export
// them; linking both would bind every call to whichever library came first).
#pragma once

#include <GL/glcorearb.h>

#include <string>

// glcorearb.h declares no pointer types for the OpenGL 1.1 entry points.
typedef void(APIENTRYP PFNGLGENTEXTURESPROC)(GLsizei n, GLuint* textures);
typedef void(APIENTRYP PFNGLDELETETEXTURESPROC)(GLsizei n, const GLuint* textures);
typedef void(APIENTRYP PFNGLBINDTEXTUREPROC)(GLenum target, GLuint texture);
typedef void(APIENTRYP PFNGLDRAWARRAYSPROC)(GLenum mode, GLint first, GLsizei count);
typedef void(APIENTRYP PFNGLTEXSUBIMAGE2DPROC)(GLenum target, GLint level, GLint xoffset, GLint yoffset,
                                               GLsizei width, GLsizei height, GLenum format, GLenum type,
                                               const void* pixels);

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
    X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage, "glRenderbufferStorage") \
    X(PFNGLGETSTRINGIPROC, GetStringi, "glGetStringi") \
    X(PFNGLCREATESHADERPROC, CreateShader, "glCreateShader") \
    X(PFNGLSHADERSOURCEPROC, ShaderSource, "glShaderSource") \
    X(PFNGLCOMPILESHADERPROC, CompileShader, "glCompileShader") \
    X(PFNGLGETSHADERIVPROC, GetShaderiv, "glGetShaderiv") \
    X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog, "glGetShaderInfoLog") \
    X(PFNGLDELETESHADERPROC, DeleteShader, "glDeleteShader") \
    X(PFNGLCREATEPROGRAMPROC, CreateProgram, "glCreateProgram") \
    X(PFNGLATTACHSHADERPROC, AttachShader, "glAttachShader") \
    X(PFNGLLINKPROGRAMPROC, LinkProgram, "glLinkProgram") \
    X(PFNGLGETPROGRAMIVPROC, GetProgramiv, "glGetProgramiv") \
    X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog, "glGetProgramInfoLog") \
    X(PFNGLDELETEPROGRAMPROC, DeleteProgram, "glDeleteProgram") \
    X(PFNGLUSEPROGRAMPROC, UseProgram, "glUseProgram") \
    X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation, "glGetUniformLocation") \
    X(PFNGLUNIFORM1IPROC, Uniform1i, "glUniform1i") \
    X(PFNGLUNIFORM4FPROC, Uniform4f, "glUniform4f") \
    X(PFNGLUNIFORM4IVPROC, Uniform4iv, "glUniform4iv") \
    X(PFNGLUNIFORM4FVPROC, Uniform4fv, "glUniform4fv") \
    X(PFNGLUNIFORM2FVPROC, Uniform2fv, "glUniform2fv") \
    X(PFNGLGENTEXTURESPROC, GenTextures, "glGenTextures") \
    X(PFNGLDELETETEXTURESPROC, DeleteTextures, "glDeleteTextures") \
    X(PFNGLBINDTEXTUREPROC, BindTexture, "glBindTexture") \
    X(PFNGLACTIVETEXTUREPROC, ActiveTexture, "glActiveTexture") \
    X(PFNGLTEXIMAGE2DPROC, TexImage2D, "glTexImage2D") \
    X(PFNGLTEXIMAGE3DPROC, TexImage3D, "glTexImage3D") \
    X(PFNGLTEXPARAMETERIPROC, TexParameteri, "glTexParameteri") \
    X(PFNGLTEXBUFFERPROC, TexBuffer, "glTexBuffer") \
    X(PFNGLGENBUFFERSPROC, GenBuffers, "glGenBuffers") \
    X(PFNGLDELETEBUFFERSPROC, DeleteBuffers, "glDeleteBuffers") \
    X(PFNGLBINDBUFFERPROC, BindBuffer, "glBindBuffer") \
    X(PFNGLBUFFERDATAPROC, BufferData, "glBufferData") \
    X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays, "glGenVertexArrays") \
    X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray, "glBindVertexArray") \
    X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays, "glDeleteVertexArrays") \
    X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer, "glVertexAttribPointer") \
    X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray, "glEnableVertexAttribArray") \
    X(PFNGLDRAWARRAYSPROC, DrawArrays, "glDrawArrays") \
    X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D, "glFramebufferTexture2D") \
    X(PFNGLDRAWBUFFERSPROC, DrawBuffers, "glDrawBuffers") \
    X(PFNGLCOLORMASKIPROC, ColorMaski, "glColorMaski") \
    X(PFNGLSCISSORPROC, Scissor, "glScissor") \
    X(PFNGLENABLEPROC, Enable, "glEnable") \
    X(PFNGLDISABLEPROC, Disable, "glDisable") \
    X(PFNGLCLIPCONTROLPROC, ClipControl, "glClipControl") \
    X(PFNGLTEXTUREBARRIERPROC, TextureBarrier, "glTextureBarrier") \
    X(PFNGLGETTEXIMAGEPROC, GetTexImage, "glGetTexImage") \
    X(PFNGLTEXSTORAGE2DPROC, TexStorage2D, "glTexStorage2D") \
    X(PFNGLTEXSUBIMAGE2DPROC, TexSubImage2D, "glTexSubImage2D") \
    X(PFNGLCLEARTEXSUBIMAGEPROC, ClearTexSubImage, "glClearTexSubImage") \
    X(PFNGLCOPYIMAGESUBDATAPROC, CopyImageSubData, "glCopyImageSubData") \
    X(PFNGLBLITFRAMEBUFFERPROC, BlitFramebuffer, "glBlitFramebuffer") \
    X(PFNGLGETTEXTURESUBIMAGEPROC, GetTextureSubImage, "glGetTextureSubImage") \
    X(PFNGLDISABLEVERTEXATTRIBARRAYPROC, DisableVertexAttribArray, "glDisableVertexAttribArray") \
    X(PFNGLGENQUERIESPROC, GenQueries, "glGenQueries") \
    X(PFNGLDELETEQUERIESPROC, DeleteQueries, "glDeleteQueries") \
    X(PFNGLBEGINQUERYPROC, BeginQuery, "glBeginQuery") \
    X(PFNGLENDQUERYPROC, EndQuery, "glEndQuery") \
    X(PFNGLGETQUERYOBJECTUI64VPROC, GetQueryObjectui64v, "glGetQueryObjectui64v") \
    X(PFNGLGENSAMPLERSPROC, GenSamplers, "glGenSamplers") \
    X(PFNGLDELETESAMPLERSPROC, DeleteSamplers, "glDeleteSamplers") \
    X(PFNGLBINDSAMPLERPROC, BindSampler, "glBindSampler") \
    X(PFNGLSAMPLERPARAMETERIPROC, SamplerParameteri, "glSamplerParameteri") \
    X(PFNGLSAMPLERPARAMETERFVPROC, SamplerParameterfv, "glSamplerParameterfv") \
    X(PFNGLBLENDFUNCSEPARATEPROC, BlendFuncSeparate, "glBlendFuncSeparate") \
    X(PFNGLBLENDEQUATIONSEPARATEPROC, BlendEquationSeparate, "glBlendEquationSeparate") \
    X(PFNGLBLENDCOLORPROC, BlendColor, "glBlendColor") \
    X(PFNGLCOLORMASKPROC, ColorMask, "glColorMask") \
    X(PFNGLDEPTHFUNCPROC, DepthFunc, "glDepthFunc") \
    X(PFNGLDEPTHMASKPROC, DepthMask, "glDepthMask")

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
