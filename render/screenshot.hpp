#pragma once
/// \file screenshot.hpp
/// The fixed recipe for the screenshot regression tests and their goldens
/// (screenshots/<level>.png): one place, so the test and the regeneration
/// command can never disagree.

#include "offscreen.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace stepwise::render {

struct ScreenshotSettings {
    int width = 960;
    int height = 540;
    long long steps = 60;  ///< one second at the default dt; 0 when World::build refuses the level
    /// Overlays that need a World are dropped when the level cannot be built.
    std::string overlays = "velocity,force-field,trails";
    /// Pixel comparison: a pixel differs when a channel differs by more
    /// than `channelTolerance` (0..255); the images match while at most
    /// `maxDifferingFraction` of the pixels differ. A rasteriser update
    /// moves edge pixels by a few levels; a moved body changes hundreds of
    /// pixels by far more.
    int channelTolerance = 32;
    double maxDifferingFraction = 0.0005;
};

struct Screenshot {
    Image image;
    long long stepsTaken = 0;
    std::string note;  ///< why the level was drawn unsimulated, or ""
};

/// Loads `level`, steps it settings.steps times when World::build accepts
/// it (else draws it as loaded) and renders it with the level's camera.
Result<Screenshot> renderLevelScreenshot(OffscreenRenderer& renderer, const std::filesystem::path& level,
                                         const ScreenshotSettings& settings = {});
/// Same, for a scene already in memory (tests move bodies with it).
Result<Screenshot> renderSceneScreenshot(OffscreenRenderer& renderer, Scene scene, const std::string& caption,
                                         const ScreenshotSettings& settings = {});

/// levels/*.json, sorted by name.
std::vector<std::filesystem::path> listLevels(const std::filesystem::path& levelsDir);

} // namespace stepwise::render
