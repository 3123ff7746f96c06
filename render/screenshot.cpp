#include "screenshot.hpp"

#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include <algorithm>
#include <optional>

namespace stepwise::render {

Result<Screenshot> renderSceneScreenshot(OffscreenRenderer& renderer, Scene scene, const std::string& caption,
                                         const ScreenshotSettings& settings) {
    Result<OverlaySet> overlays = parseOverlayList(settings.overlays);
    if (!overlays) return Error{overlays.error()};
    Screenshot shot;
    TrailRecorder trails(48);
    // The camera is fixed from the loaded scene, as `stepwise render` does.
    FrameInput input;
    input.camera = sceneCamera(scene, renderer.width(), renderer.height());
    input.overlays = *overlays;
    std::optional<World> world;
    Result<World> built = World::build(scene);
    if (built) {
        world.emplace(std::move(*built));
        trails.record(*world);
        const AdvanceResult run = advance(*world, std::uint64_t(std::max(0LL, settings.steps)),
                                          {.afterStep = [&](std::uint64_t) {
                                              trails.record(*world);
                                              return true;
                                          }});
        shot.stepsTaken = (long long)run.taken;
        if (run.divergence) return run.divergence->within("diverged");
        world->writeBack(scene);
    } else {
        shot.note = built.error();
        trails.record(scene);
        // Drawn as loaded; overlays that need the simulation are left out
        // rather than drawn as "unavailable" notes.
        input.overlays.bits &= ~(std::uint32_t(Overlay::Force) | std::uint32_t(Overlay::NetForce) |
                                 std::uint32_t(Overlay::ForceField) | std::uint32_t(Overlay::Contacts) |
                                 std::uint32_t(Overlay::Joints));
    }
    input.scene = &scene;
    input.world = world ? &*world : nullptr;
    input.trails = &trails;
    input.caption = caption + "  |  step " + std::to_string(shot.stepsTaken);
    shot.image = renderer.capture(input);
    return shot;
}

Result<Screenshot> renderLevelScreenshot(OffscreenRenderer& renderer, const std::filesystem::path& level,
                                         const ScreenshotSettings& settings) {
    Result<Scene> scene = loadSceneFile(level);
    if (!scene) return Error{scene.error()};
    return renderSceneScreenshot(renderer, std::move(*scene), level.filename().string(), settings);
}

std::vector<std::filesystem::path> listLevels(const std::filesystem::path& levelsDir) {
    std::vector<std::filesystem::path> levels;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(levelsDir, ec))
        if (entry.is_regular_file() && entry.path().extension() == ".json" &&
            entry.path().filename() != "scene.schema.json")
            levels.push_back(entry.path());
    std::sort(levels.begin(), levels.end());
    return levels;
}

} // namespace stepwise::render
