#pragma once
// The golden-image harness of the screenshot tests (test_screenshots: levels
// through the renderer; test_editor_screenshots: the whole editor UI): one
// comparison with the renderer's tolerance (render/screenshot.hpp), one
// message, one place the failing images go.

#include "image.hpp"
#include "screenshot.hpp"

#include "stepwise/scene_io.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace stepwise::test {

namespace fs = std::filesystem;

/// STEPWISE_UPDATE_GOLDENS=1: the tests write their goldens instead of
/// comparing (look at every image before committing).
inline bool updatingGoldens() {
    const char* v = std::getenv("STEPWISE_UPDATE_GOLDENS");
    return v && std::string(v) == "1";
}

/// Compares `actual` with the PNG `golden`. On failure writes
/// <failures>/<stem>-actual.png and -diff.png and says where, how many pixels
/// differ and within which box.
inline ::testing::AssertionResult matchesGolden(const render::Image& actual, const fs::path& golden, const fs::path& failures,
                                                const std::string& stem) {
    const render::ScreenshotSettings settings;
    Result<render::Image> expected = render::readPng(golden.string());
    if (!expected)
        return ::testing::AssertionFailure()
               << expected.error() << "\n  (no golden? regenerate: cmake --build build --target update-goldens)";
    const render::ImageDiff diff = render::compareImages(*expected, actual, settings.channelTolerance);
    const bool ok = diff.sameSize && diff.fraction() <= settings.maxDifferingFraction;
    if (ok) return ::testing::AssertionSuccess();
    fs::create_directories(failures);
    const fs::path actualPath = failures / (stem + "-actual.png");
    const fs::path diffPath = failures / (stem + "-diff.png");
    (void)writeFileAtomically(actualPath, render::encodePng(actual));
    if (diff.sameSize) (void)writeFileAtomically(diffPath, render::encodePng(diff.visual));
    auto failure = ::testing::AssertionFailure();
    if (!diff.sameSize) {
        failure << "size differs: golden " << expected->width << "x" << expected->height << ", actual "
                << actual.width << "x" << actual.height;
    } else {
        failure << diff.differing << " of " << diff.total << " pixels differ by more than "
                << settings.channelTolerance << "/255 (" << 100.0 * diff.fraction() << "%, allowed "
                << 100.0 * settings.maxDifferingFraction << "%), within x " << diff.x0 << ".." << diff.x1
                << ", y " << diff.y0 << ".." << diff.y1 << " (top-left origin); largest delta " << diff.maxDelta;
    }
    failure << "\n  golden: " << golden.string() << "\n  actual: " << actualPath.string();
    if (diff.sameSize) failure << "\n  diff:   " << diffPath.string() << " (differing pixels in magenta)";
    return failure;
}

} // namespace stepwise::test
