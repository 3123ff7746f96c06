#include "offscreen.hpp"

#include <GL/osmesa.h>

#include <vector>

namespace stepwise::render {

namespace {
void* osmesaProc(const char* name) {
    // OSMesa hands out core entry points through its own lookup.
    return reinterpret_cast<void*>(OSMesaGetProcAddress(name));
}
} // namespace

struct OffscreenRenderer::Context {
    OSMesaContext context = nullptr;
    std::vector<unsigned char> buffer;  // RGBA8, owned here, drawn into by Mesa
    ~Context() {
        if (context) OSMesaDestroyContext(context);
    }
};

std::optional<Error> OffscreenRenderer::sizeProblem(int widthPx, int heightPx) {
    const std::string size = std::to_string(widthPx) + "x" + std::to_string(heightPx);
    if (widthPx <= 0 || heightPx <= 0 || widthPx > kMaxSidePx || heightPx > kMaxSidePx)
        return Error{"image size " + size + " is outside 1.." + std::to_string(kMaxSidePx) + " pixels a side"};
    const long long pixels = (long long)widthPx * heightPx;
    if (pixels > kMaxPixels)
        return Error{"image size " + size + " is " + std::to_string(pixels) + " pixels; the limit is " +
                     std::to_string(kMaxPixels) + " (7680x4320)"};
    return std::nullopt;
}

Result<std::unique_ptr<OffscreenRenderer>> OffscreenRenderer::create(int widthPx, int heightPx) {
    if (std::optional<Error> problem = sizeProblem(widthPx, heightPx)) return *problem;
    std::unique_ptr<OffscreenRenderer> r(new OffscreenRenderer());
    r->context_ = std::make_unique<Context>();
    // No depth or stencil: 2D drawing in painter's order needs neither.
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA,         OSMESA_DEPTH_BITS, 0,
                           OSMESA_STENCIL_BITS, 0,             OSMESA_ACCUM_BITS, 0,
                           OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 3,
                           OSMESA_CONTEXT_MINOR_VERSION, 3,    0};
    r->context_->context = OSMesaCreateContextAttribs(attribs, nullptr);
    if (!r->context_->context)
        return Error{"cannot create an OSMesa OpenGL 3.3 core context", "", ErrorKind::Environment};
    r->context_->buffer.assign(std::size_t(widthPx) * std::size_t(heightPx) * 4, 0);
    if (!OSMesaMakeCurrent(r->context_->context, r->context_->buffer.data(), GL_UNSIGNED_BYTE, widthPx, heightPx))
        return Error{"cannot make the OSMesa context current", "", ErrorKind::Environment};
    r->width_ = widthPx;
    r->height_ = heightPx;
    Result<std::unique_ptr<Renderer>> renderer = Renderer::create(osmesaProc);
    if (!renderer) return Error{renderer.error(), "", ErrorKind::Environment};
    r->renderer_ = std::move(*renderer);
    return r;
}

OffscreenRenderer::~OffscreenRenderer() {
    renderer_.reset();  // GL objects go while the context still exists
}

Image OffscreenRenderer::capture(const FrameInput& input, DrawData* drawn) {
    DrawData data = renderer_->render(input, width_, height_);
    Image image = renderer_->readPixels(width_, height_);
    if (drawn) *drawn = std::move(data);
    return image;
}

} // namespace stepwise::render
