#pragma once
/// \file image.hpp
/// RGB8 images, PNG encoding to memory and decoding, and the tolerant
/// comparison the screenshot tests use.

#include "stepwise/result.hpp"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace stepwise::render {

/// Top-down rows of RGB bytes.
struct Image {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgb;  ///< width*height*3 bytes
    std::uint8_t* pixel(int x, int y) { return &rgb[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3]; }
    const std::uint8_t* pixel(int x, int y) const {
        return &rgb[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3];
    }
};

/// PNG file bytes (deterministic: same pixels, same bytes).
std::string encodePng(const Image& image);
/// Decodes PNG bytes to RGB8; `name` prefixes the error message.
Result<Image> decodePng(std::string_view bytes, std::string_view name);
/// Reads and decodes a PNG file.
Result<Image> readPng(const std::string& path);

/// Result of comparing two images of the same size.
struct ImageDiff {
    bool sameSize = true;
    std::size_t differing = 0;   ///< pixels where some channel differs by more than the tolerance
    std::size_t total = 0;
    int maxDelta = 0;            ///< largest channel difference anywhere, 0..255
    int x0 = 0, y0 = 0, x1 = -1, y1 = -1;  ///< bounding box of differing pixels (inclusive; empty when x1 < x0)
    Image visual;                ///< the expected image dimmed, differing pixels in magenta
    double fraction() const { return total ? double(differing) / double(total) : 0.0; }
};

/// A pixel differs when any channel differs by more than `channelTolerance`.
ImageDiff compareImages(const Image& expected, const Image& actual, int channelTolerance);

} // namespace stepwise::render
