#include "image.hpp"

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace stepwise::render {

std::string encodePng(const Image& image) {
    std::string bytes;
    auto append = [](void* context, void* data, int size) {
        static_cast<std::string*>(context)->append(static_cast<const char*>(data), std::size_t(size));
    };
    stbi_write_png_to_func(append, &bytes, image.width, image.height, 3, image.rgb.data(), image.width * 3);
    return bytes;
}

Result<Image> decodePng(std::string_view bytes, std::string_view name) {
    int w = 0, h = 0, channels = 0;
    unsigned char* data = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(bytes.data()), int(bytes.size()),
                                                &w, &h, &channels, 3);
    if (!data) return Error{std::string(name) + ": not a readable PNG (" + stbi_failure_reason() + ")"};
    Image image{w, h, std::vector<std::uint8_t>(data, data + std::size_t(w) * std::size_t(h) * 3)};
    stbi_image_free(data);
    return image;
}

Result<Image> readPng(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return Error{path + ": cannot open"};
    std::ostringstream buffer;
    buffer << in.rdbuf();
    return decodePng(buffer.str(), path);
}

ImageDiff compareImages(const Image& expected, const Image& actual, int channelTolerance) {
    ImageDiff diff;
    if (expected.width != actual.width || expected.height != actual.height) {
        diff.sameSize = false;
        return diff;
    }
    const int w = expected.width, h = expected.height;
    diff.total = std::size_t(w) * std::size_t(h);
    diff.x0 = w;
    diff.y0 = h;
    diff.visual = Image{w, h, std::vector<std::uint8_t>(diff.total * 3)};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::uint8_t* a = expected.pixel(x, y);
            const std::uint8_t* b = actual.pixel(x, y);
            int delta = 0;
            for (int c = 0; c < 3; ++c) delta = std::max(delta, std::abs(int(a[c]) - int(b[c])));
            diff.maxDelta = std::max(diff.maxDelta, delta);
            std::uint8_t* out = diff.visual.pixel(x, y);
            if (delta > channelTolerance) {
                ++diff.differing;
                diff.x0 = std::min(diff.x0, x);
                diff.y0 = std::min(diff.y0, y);
                diff.x1 = std::max(diff.x1, x);
                diff.y1 = std::max(diff.y1, y);
                out[0] = 255, out[1] = 0, out[2] = 255;
            } else {
                // Context: the expected image at a third of its brightness.
                for (int c = 0; c < 3; ++c) out[c] = std::uint8_t(a[c] / 3);
            }
        }
    return diff;
}

} // namespace stepwise::render
