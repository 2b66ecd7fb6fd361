/// \file gl_functions.hpp
/// The project's own OpenGL 3.3 core function loader. Entry points are fetched through the
/// context provider's get-proc-address (OSMesaGetProcAddress or glfwGetProcAddress), never by
/// linking libGL, so that the same code drives an OSMesa buffer and a GLFW window.
/// Names drop the `gl` prefix: `gl.Clear(...)` calls glClear.
#pragma once

#include <stdexcept>
#include <string>

#define GL_GLEXT_PROTOTYPES 0
#include <GL/glcorearb.h>

namespace caliper::render {

/// OpenGL 1.1 entry point types, declared here because glcorearb.h omits them when GL/gl.h
/// (pulled in by osmesa.h or glfw3.h) was included first.
namespace gl11 {
using PolygonOffset = void (*)(GLfloat factor, GLfloat units);
using DrawArrays = void (*)(GLenum mode, GLint first, GLsizei count);
using DrawElements = void (*)(GLenum mode, GLsizei count, GLenum type, const void* indices);
using GenTextures = void (*)(GLsizei n, GLuint* textures);
using BindTexture = void (*)(GLenum target, GLuint texture);
using TexSubImage2D = void (*)(GLenum target, GLint level, GLint x, GLint y, GLsizei width,
                               GLsizei height, GLenum format, GLenum type, const void* pixels);
using DeleteTextures = void (*)(GLsizei n, const GLuint* textures);
}  // namespace gl11

/// Thrown when a GL context cannot be created, a function cannot be loaded, a shader fails to
/// compile, or a GL error is detected. The message names the call and the reason.
class RenderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A generic GL entry point (cast to its real type before the call).
using GlProc = void (*)();
/// Address lookup of one GL entry point (returns nullptr when missing).
using GlProcLoader = GlProc (*)(const char* name, void* user);

// X(type, name): every entry point the renderer, the editor's ImGui drawing and the VR app use.
#define CALIPER_GL_FUNCTIONS(X)                                              \
  X(PFNGLCLEARPROC, Clear)                                                   \
  X(PFNGLCLEARCOLORPROC, ClearColor)                                         \
  X(PFNGLCLEARDEPTHPROC, ClearDepth)                                         \
  X(PFNGLENABLEPROC, Enable)                                                 \
  X(PFNGLDISABLEPROC, Disable)                                               \
  X(PFNGLISENABLEDPROC, IsEnabled)                                           \
  X(PFNGLVIEWPORTPROC, Viewport)                                             \
  X(PFNGLSCISSORPROC, Scissor)                                               \
  X(PFNGLDEPTHFUNCPROC, DepthFunc)                                           \
  X(PFNGLDEPTHMASKPROC, DepthMask)                                           \
  X(PFNGLBLENDFUNCPROC, BlendFunc)                                           \
  X(PFNGLBLENDFUNCSEPARATEPROC, BlendFuncSeparate)                           \
  X(PFNGLBLENDEQUATIONPROC, BlendEquation)                                   \
  X(PFNGLPOLYGONMODEPROC, PolygonMode)                                       \
  X(gl11::PolygonOffset, PolygonOffset)                                      \
  X(PFNGLLINEWIDTHPROC, LineWidth)                                           \
  X(PFNGLCULLFACEPROC, CullFace)                                             \
  X(PFNGLFRONTFACEPROC, FrontFace)                                           \
  X(PFNGLGETERRORPROC, GetError)                                             \
  X(PFNGLGETSTRINGPROC, GetString)                                           \
  X(PFNGLGETINTEGERVPROC, GetIntegerv)                                       \
  X(PFNGLREADPIXELSPROC, ReadPixels)                                         \
  X(PFNGLPIXELSTOREIPROC, PixelStorei)                                       \
  X(PFNGLFINISHPROC, Finish)                                                 \
  X(PFNGLCREATESHADERPROC, CreateShader)                                     \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                                     \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                                   \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                                       \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                             \
  X(PFNGLDELETESHADERPROC, DeleteShader)                                     \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)                                   \
  X(PFNGLATTACHSHADERPROC, AttachShader)                                     \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                                       \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                     \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                           \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                                   \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                                         \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                         \
  X(PFNGLBINDATTRIBLOCATIONPROC, BindAttribLocation)                         \
  X(PFNGLUNIFORM1IPROC, Uniform1i)                                           \
  X(PFNGLUNIFORM1FPROC, Uniform1f)                                           \
  X(PFNGLUNIFORM2FPROC, Uniform2f)                                           \
  X(PFNGLUNIFORM3FVPROC, Uniform3fv)                                         \
  X(PFNGLUNIFORM4FVPROC, Uniform4fv)                                         \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)                             \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                               \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                               \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                         \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                                         \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                                         \
  X(PFNGLBUFFERDATAPROC, BufferData)                                         \
  X(PFNGLBUFFERSUBDATAPROC, BufferSubData)                                   \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                                   \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)                       \
  X(PFNGLVERTEXATTRIB4FPROC, VertexAttrib4f)                                 \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)               \
  X(PFNGLDISABLEVERTEXATTRIBARRAYPROC, DisableVertexAttribArray)             \
  X(gl11::DrawArrays, DrawArrays)                                            \
  X(gl11::DrawElements, DrawElements)                                        \
  X(gl11::GenTextures, GenTextures)                                          \
  X(gl11::BindTexture, BindTexture)                                          \
  X(PFNGLTEXIMAGE2DPROC, TexImage2D)                                         \
  X(gl11::TexSubImage2D, TexSubImage2D)                                      \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri)                                   \
  X(gl11::DeleteTextures, DeleteTextures)                                    \
  X(PFNGLACTIVETEXTUREPROC, ActiveTexture)                                   \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                               \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                               \
  X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)                     \
  X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer)               \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)                 \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                         \
  X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers)                             \
  X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer)                             \
  X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage)                       \
  X(PFNGLRENDERBUFFERSTORAGEMULTISAMPLEPROC, RenderbufferStorageMultisample) \
  X(PFNGLDELETERENDERBUFFERSPROC, DeleteRenderbuffers)                       \
  X(PFNGLBLITFRAMEBUFFERPROC, BlitFramebuffer)

/// A table of GL entry points for one context. Load it once the context is current.
struct GlFunctions {
#define CALIPER_GL_MEMBER(type, name) type name = nullptr;
  CALIPER_GL_FUNCTIONS(CALIPER_GL_MEMBER)
#undef CALIPER_GL_MEMBER

  /// Loads every entry point with `loader`; throws RenderError naming the first missing one.
  void load(GlProcLoader loader, void* user);

  /// Throws RenderError("<what>: GL error 0x0502 ...") when glGetError reports an error.
  void check(const char* what) const;
};

/// Compiles a vertex and a fragment shader and links them into a program. Throws RenderError
/// with the compiler's or linker's log, naming `name`; nothing is left allocated on failure.
/// `vertex_prelude` (e.g. shaders::kUnlitVertex), when given, is compiled into the vertex shader
/// right after the first line of `vertex_source` (its #version line); the compiler's line
/// numbers still count the lines of `vertex_source`. `fragment_prelude` does the same for the
/// fragment shader (e.g. a #define that selects a variant).
GLuint link_program(const GlFunctions& gl, const char* vertex_source, const char* fragment_source,
                    const char* name, const char* vertex_prelude = nullptr,
                    const char* fragment_prelude = nullptr);

}  // namespace caliper::render
