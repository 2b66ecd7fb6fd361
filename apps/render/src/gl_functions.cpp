#include "render/gl_functions.hpp"

#include <cstdio>
#include <cstring>
#include <string>

namespace caliper::render {

void GlFunctions::load(GlProcLoader loader, void* user) {
#define CALIPER_GL_LOAD(type, name)                                                        \
  name = reinterpret_cast<type>(loader("gl" #name, user));                                 \
  if ((name) == nullptr) {                                                                 \
    throw RenderError("OpenGL entry point gl" #name                                        \
                      " is missing: the context must support OpenGL 3.3 core (Mesa 20+)"); \
  }
  CALIPER_GL_FUNCTIONS(CALIPER_GL_LOAD)
#undef CALIPER_GL_LOAD
}

void GlFunctions::check(const char* what) const {
  const GLenum err = GetError();
  if (err != GL_NO_ERROR) {
    char code[16];
    std::snprintf(code, sizeof code, "0x%04X", static_cast<unsigned>(err));
    throw RenderError(std::string(what) + ": OpenGL error " + code);
  }
}

namespace {

// When `status` (GL_COMPILE_STATUS, GL_LINK_STATUS) of shader or program `id` is false: deletes
// it and throws RenderError(`failure` + its info log). Shaders and programs differ only in the
// entry points (get_iv, get_log, destroy).
template <class GetIv, class GetLog, class Destroy>
void check_status(GLuint id, GLenum status, GetIv get_iv, GetLog get_log, Destroy destroy,
                  const std::string& failure) {
  GLint ok = 0;
  get_iv(id, status, &ok);
  if (ok) return;
  char log[2048] = {0};
  get_log(id, sizeof log, nullptr, log);
  destroy(id);
  throw RenderError(failure + log);
}

// Compiles `source`. With a `prelude`, the shader text is the first line of `source` (its
// #version line), the prelude, a #line directive that numbers the next line 2, and the rest of
// `source`: the compiler's messages keep the line numbers of `source`.
GLuint compile_shader(const GlFunctions& gl, GLenum type, const char* source, const char* name,
                      const char* prelude = nullptr) {
  const char* first_line_end = prelude != nullptr ? std::strchr(source, '\n') : nullptr;
  if (prelude != nullptr && first_line_end == nullptr)
    throw RenderError(std::string("shader ") + name + " has no line after its #version line");
  GLuint s = gl.CreateShader(type);
  if (prelude == nullptr) {
    gl.ShaderSource(s, 1, &source, nullptr);
  } else {
    const char* parts[4] = {source, prelude, "\n#line 2\n", first_line_end + 1};
    const GLint lengths[4] = {static_cast<GLint>(first_line_end + 1 - source), -1, -1, -1};
    gl.ShaderSource(s, 4, parts, lengths);
  }
  gl.CompileShader(s);
  check_status(s, GL_COMPILE_STATUS, gl.GetShaderiv, gl.GetShaderInfoLog, gl.DeleteShader,
               std::string("shader ") + name + " failed to compile: ");
  return s;
}

}  // namespace

GLuint link_program(const GlFunctions& gl, const char* vs, const char* fs, const char* name,
                    const char* vertex_prelude, const char* fragment_prelude) {
  GLuint v = compile_shader(gl, GL_VERTEX_SHADER, vs, name, vertex_prelude);
  GLuint f = 0;
  try {
    f = compile_shader(gl, GL_FRAGMENT_SHADER, fs, name, fragment_prelude);
  } catch (...) {
    gl.DeleteShader(v);
    throw;
  }
  GLuint p = gl.CreateProgram();
  gl.AttachShader(p, v);
  gl.AttachShader(p, f);
  gl.LinkProgram(p);
  gl.DeleteShader(v);
  gl.DeleteShader(f);
  check_status(p, GL_LINK_STATUS, gl.GetProgramiv, gl.GetProgramInfoLog, gl.DeleteProgram,
               std::string("shader program ") + name + " failed to link: ");
  return p;
}

}  // namespace caliper::render
