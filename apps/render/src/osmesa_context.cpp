// OSMesa off-screen context provider (Mesa llvmpipe), OpenGL 3.3 core profile.
// render/context.hpp (GL/glcorearb.h) must come before GL/osmesa.h (which pulls in GL/gl.h).
#include "render/context.hpp"

#include <GL/osmesa.h>

#include <string>
#include <vector>

namespace caliper::render {

Image GlContext::read_pixels() {
  make_current();
  Image img;
  img.width = width();
  img.height = height();
  img.rgba.resize(4 * static_cast<size_t>(img.width) * img.height);
  gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  gl_.PixelStorei(GL_PACK_ALIGNMENT, 1);
  std::vector<std::uint8_t> rows(img.rgba.size());
  gl_.ReadPixels(0, 0, img.width, img.height, GL_RGBA, GL_UNSIGNED_BYTE, rows.data());
  gl_.check("glReadPixels");
  const size_t stride = 4 * static_cast<size_t>(img.width);
  for (int y = 0; y < img.height; ++y) {  // GL's first row is the bottom one
    std::copy(rows.begin() + static_cast<std::ptrdiff_t>(stride * (img.height - 1 - y)),
              rows.begin() + static_cast<std::ptrdiff_t>(stride * (img.height - y)),
              img.rgba.begin() + static_cast<std::ptrdiff_t>(stride * y));
  }
  return img;
}

namespace {

GlProc osmesa_loader(const char* name, void*) {
  return reinterpret_cast<GlProc>(OSMesaGetProcAddress(name));
}

class OsMesaGlContext final : public GlContext {
 public:
  OsMesaGlContext(int w, int h) : width_(w), height_(h) {
    if (w <= 0 || h <= 0 || w > 16384 || h > 16384) {
      throw RenderError("OSMesa context: size " + std::to_string(w) + " x " + std::to_string(h) +
                        " is out of range (1..16384)");
    }
    const int attribs[] = {OSMESA_FORMAT,
                           OSMESA_RGBA,
                           OSMESA_DEPTH_BITS,
                           24,
                           OSMESA_STENCIL_BITS,
                           8,
                           OSMESA_PROFILE,
                           OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION,
                           3,
                           OSMESA_CONTEXT_MINOR_VERSION,
                           3,
                           0};
    ctx_ = OSMesaCreateContextAttribs(attribs, nullptr);
    if (ctx_ == nullptr) {
      throw RenderError(
          "OSMesa could not create an OpenGL 3.3 core context: install Debian's libosmesa6 "
          "(Mesa 20 or newer) and make sure LIBGL_ALWAYS_SOFTWARE / GALLIUM_DRIVER do not force "
          "a driver without GL 3.3");
    }
    buffer_.resize(4 * static_cast<size_t>(w) * h);
    make_current();
    gl_.load(osmesa_loader, nullptr);
  }
  ~OsMesaGlContext() override { OSMesaDestroyContext(ctx_); }

  void make_current() override {
    // Already current with our buffer: OSMesaMakeCurrent would re-validate the framebuffer.
    if (OSMesaGetCurrentContext() == ctx_) return;
    if (!OSMesaMakeCurrent(ctx_, buffer_.data(), GL_UNSIGNED_BYTE, width_, height_)) {
      throw RenderError("OSMesaMakeCurrent failed for a " + std::to_string(width_) + " x " +
                        std::to_string(height_) + " buffer");
    }
  }
  int width() const override { return width_; }
  int height() const override { return height_; }
  void swap_buffers() override { gl_.Finish(); }

 private:
  OSMesaContext ctx_ = nullptr;
  int width_, height_;
  std::vector<std::uint8_t> buffer_;
};

}  // namespace

std::unique_ptr<GlContext> make_osmesa_context(int width, int height) {
  return std::make_unique<OsMesaGlContext>(width, height);
}

}  // namespace caliper::render
