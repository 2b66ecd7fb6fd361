#include "render/gl_functions.hpp"

#include <cstdio>

namespace caliper::render {

void GlFunctions::load(GlProcLoader loader, void* user) {
#define CALIPER_GL_LOAD(type, name)                                                        \
  name = reinterpret_cast<type>(loader("gl" #name, user));                                 \
  if (name == nullptr) {                                                                   \
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

}  // namespace caliper::render
