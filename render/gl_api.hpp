#pragma once
/// \file gl_api.hpp
/// The OpenGL 3.3 core entry points the renderer uses, loaded at run time
/// through a caller-supplied lookup (OSMesaGetProcAddress headless,
/// SDL_GL_GetProcAddress in the editor window). The render library links no
/// GL library itself, so the one drawing path serves both contexts.

#include <GL/glcorearb.h>

#include <string>

namespace stepwise::render {

/// Looks up a GL entry point by name; returns nullptr when absent.
using GetProcAddress = void* (*)(const char* name);

// X-macro list: (type of the pointer, name without the "gl" prefix).
#define STEPWISE_GL_FUNCTIONS(X)                                   \
    X(PFNGLVIEWPORTPROC, Viewport)                                 \
    X(PFNGLCLEARCOLORPROC, ClearColor)                             \
    X(PFNGLCLEARPROC, Clear)                                       \
    X(PFNGLENABLEPROC, Enable)                                     \
    X(PFNGLDISABLEPROC, Disable)                                   \
    X(PFNGLBLENDFUNCSEPARATEPROC, BlendFuncSeparate)               \
    X(PFNGLCREATESHADERPROC, CreateShader)                         \
    X(PFNGLSHADERSOURCEPROC, ShaderSource)                         \
    X(PFNGLCOMPILESHADERPROC, CompileShader)                       \
    X(PFNGLGETSHADERIVPROC, GetShaderiv)                           \
    X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                 \
    X(PFNGLDELETESHADERPROC, DeleteShader)                         \
    X(PFNGLCREATEPROGRAMPROC, CreateProgram)                       \
    X(PFNGLATTACHSHADERPROC, AttachShader)                         \
    X(PFNGLLINKPROGRAMPROC, LinkProgram)                           \
    X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                         \
    X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)               \
    X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                       \
    X(PFNGLUSEPROGRAMPROC, UseProgram)                             \
    X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)             \
    X(PFNGLUNIFORM1IPROC, Uniform1i)                               \
    X(PFNGLUNIFORM1FPROC, Uniform1f)                               \
    X(PFNGLUNIFORM2FPROC, Uniform2f)                               \
    X(PFNGLUNIFORM3FPROC, Uniform3f)                               \
    X(PFNGLUNIFORM4FPROC, Uniform4f)                               \
    X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                   \
    X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                   \
    X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)             \
    X(PFNGLGENBUFFERSPROC, GenBuffers)                             \
    X(PFNGLBINDBUFFERPROC, BindBuffer)                             \
    X(PFNGLBUFFERDATAPROC, BufferData)                             \
    X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                       \
    X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)           \
    X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)   \
    X(PFNGLVERTEXATTRIBDIVISORPROC, VertexAttribDivisor)           \
    X(PFNGLDRAWARRAYSPROC, DrawArrays)                             \
    X(PFNGLDRAWARRAYSINSTANCEDPROC, DrawArraysInstanced)           \
    X(PFNGLDRAWELEMENTSPROC, DrawElements)                         \
    X(PFNGLREADPIXELSPROC, ReadPixels)                             \
    X(PFNGLPIXELSTOREIPROC, PixelStorei)                           \
    X(PFNGLGETERRORPROC, GetError)                                 \
    X(PFNGLGETSTRINGPROC, GetString)                               \
    X(PFNGLFINISHPROC, Finish)                                     \
    X(PFNGLFLUSHPROC, Flush)                                       \
    /* the editor's ImGui pass and viewport target (ui/imgui_gl.cpp) */ \
    X(PFNGLSCISSORPROC, Scissor)                                   \
    X(PFNGLBLENDEQUATIONPROC, BlendEquation)                       \
    X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)                 \
    X(PFNGLGENTEXTURESPROC, GenTextures)                           \
    X(PFNGLBINDTEXTUREPROC, BindTexture)                           \
    X(PFNGLTEXIMAGE2DPROC, TexImage2D)                             \
    X(PFNGLTEXPARAMETERIPROC, TexParameteri)                       \
    X(PFNGLDELETETEXTURESPROC, DeleteTextures)                     \
    X(PFNGLACTIVETEXTUREPROC, ActiveTexture)                       \
    X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                   \
    X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                   \
    X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)         \
    X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)     \
    X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)

/// Function pointers, one per entry point above (`gl.Viewport(...)`).
struct GlApi {
#define STEPWISE_GL_DECLARE(type, name) type name = nullptr;
    STEPWISE_GL_FUNCTIONS(STEPWISE_GL_DECLARE)
#undef STEPWISE_GL_DECLARE

    /// Loads every entry point; returns "" or the name of the first missing one.
    std::string load(GetProcAddress getProc);
};

/// Compiles a vertex and a fragment shader from full sources and links
/// them; `label` names them in the error. Returns the program, or 0 with
/// the compiler's or linker's log in `error`.
GLuint linkProgram(const GlApi& gl, const std::string& vertexSource, const std::string& fragmentSource,
                   const std::string& label, std::string& error);

} // namespace stepwise::render
