// render_bench: 10,000 bodies at 1920x1080 with every overlay on, through
// OSMesa/llvmpipe. Reports milliseconds per frame split into the CPU half
// (buildDrawData) and the GL half (submit + rasterise + read back), and the
// PNG encode on the side. Not a ctest test: timing depends on the machine.
//
//   build/render_bench [--bodies N] [--width W] [--height H] [--frames F] [--overlay LIST] [--out FILE.png]
//                      [--level FILE --steps N --trail N] [--no-pixel-layers] [--batches]
//
// --level draws a saved level instead of the generated scene, after N steps
// (default 32) with the last `--trail` steps (default 32) as trails, through
// the level's camera: the editor's viewport in its bench (`stepwise edit
// --bench-bodies 2000`, saved with the script line `saveas`) is
// `--level pile.json --steps 600 --trail 64 --width 720 --height 476`.
// --no-pixel-layers draws crowded AABB outlines as quads (BuildOptions);
// --batches lists the first frame's batches.

#include "offscreen.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <ctime>
#include <vector>

using namespace stepwise;
using namespace stepwise::render;

namespace {

/// Deterministic pseudo-random numbers in [0, 1) (64-bit LCG, top bits).
struct Lcg {
    std::uint64_t state = 0x9E3779B97F4A7C15ull;
    double next() {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return double(state >> 11) * (1.0 / 9007199254740992.0);
    }
};

Scene makeScene(int bodies) {
    Scene scene;
    scene.world.gravity = {0.0, -9.81};
    scene.world.G = 30.0;
    Lcg rng;
    const double width = 120.0, height = 66.0;  // metres, roughly 16:9
    auto add = [&](auto&&... components) {
        Entity e = scene.registry.create();
        (scene.registry.emplace(e, components), ...);
        return e;
    };
    add(Name{"floor"}, Plane{{0.0, 1.0}, -0.5 * height - 1.0}, Color{{0.45, 0.55, 0.68}});
    for (int a = 0; a < 4; ++a)
        add(Name{std::string("sun").append(std::to_string(a))}, Position{{(a - 1.5) * 28.0, 8.0 * ((a % 2) ? 1 : -1)}}, Static{true},
            Mass{40.0}, Attractor{0.5}, Radius{0.8}, Color{{1.0, 0.8, 0.4}});
    std::vector<Entity> made;
    made.reserve(std::size_t(bodies));
    for (int i = 0; i < bodies; ++i) {
        const Vec2 p{(rng.next() - 0.5) * width, (rng.next() - 0.5) * height};
        const Vec2 v{(rng.next() - 0.5) * 8.0, (rng.next() - 0.5) * 8.0};
        const Rgb c{0.35 + 0.6 * rng.next(), 0.45 + 0.4 * rng.next(), 0.6 + 0.4 * rng.next()};
        Entity e = add(Name{std::string("b").append(std::to_string(i))}, Position{p}, Velocity{v}, Mass{0.5 + rng.next()}, Color{c},
                       Angle{rng.next() * 6.28});
        made.push_back(e);
        if (i % 4 == 3)
            scene.registry.emplace(e, Box{0.25 + 0.3 * rng.next(), 0.15 + 0.2 * rng.next()});
        else
            scene.registry.emplace(e, Radius{0.08 + 0.15 * rng.next()});
    }
    // A few hundred springs between neighbours in creation order.
    for (int i = 0; i + 1 < bodies && i < 600; i += 3)
        add(Name{std::string("s").append(std::to_string(i))},
            Spring{made[std::size_t(i)], made[std::size_t(i) + 1], std::nullopt, 5.0, 0.1, 1.0});
    return scene;
}

double ms(std::chrono::steady_clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

/// CPU time of the whole process (every llvmpipe thread included), ms: on a
/// shared machine it moves less than the wall clock.
double cpuMs(clockid_t clock) {
    timespec t{};
    clock_gettime(clock, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}
double processCpuMs() { return cpuMs(CLOCK_PROCESS_CPUTIME_ID); }

} // namespace

int main(int argc, char** argv) {
    int bodies = 10000, width = 1920, height = 1080, frames = 10, steps = 32, trail = 32;
    std::string out, overlays = "all", level;
    BuildOptions options;
    bool batches = false;
    for (int i = 1; i < argc; i += 2) {
        if (!std::strcmp(argv[i], "--no-pixel-layers")) {
            options.pixelLayers = false;
            --i;
            continue;
        }
        if (!std::strcmp(argv[i], "--batches")) {
            batches = true;
            --i;
            continue;
        }
        if (i + 1 >= argc) {
            std::fprintf(stderr, "render_bench: %s needs a value\n", argv[i]);
            return 2;
        }
        if (!std::strcmp(argv[i], "--bodies")) bodies = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--width")) width = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--height")) height = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--frames")) frames = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--out")) out = argv[i + 1];
        else if (!std::strcmp(argv[i], "--overlay")) overlays = argv[i + 1];
        else if (!std::strcmp(argv[i], "--level")) level = argv[i + 1];
        else if (!std::strcmp(argv[i], "--steps")) steps = std::max(1, std::atoi(argv[i + 1]));
        else if (!std::strcmp(argv[i], "--trail")) trail = std::max(2, std::atoi(argv[i + 1]));
        else {
            std::fprintf(stderr, "render_bench: unknown argument %s\n", argv[i]);
            return 2;
        }
    }
    Scene scene;
    if (level.empty()) {
        scene = makeScene(bodies);
    } else {
        Result<Scene> loaded = loadSceneFile(level);
        if (!loaded) {
            std::fprintf(stderr, "render_bench: %s\n", loaded.error().c_str());
            return 2;
        }
        scene = std::move(*loaded);
        bodies = int(scene.registry.size());
    }
    // The World is the whole scene, shapes and collisions included, so the
    // contacts overlay has the contacts of the last step to draw.
    Result<World> built = World::build(scene);
    std::optional<World> world;
    if (built) world.emplace(std::move(*built));
    else std::fprintf(stderr, "render_bench: no World (%s); force overlays skipped\n", built.error().c_str());

    TrailRecorder trails{std::size_t(trail)};
    if (world) {
        // `steps` steps, the last `trail` of them recorded for the trails overlay.
        trails.record(*world);
        advance(*world, std::uint64_t(steps - 1), {.afterStep = [&](std::uint64_t) {
                    trails.record(*world);
                    return true;
                }});
        world->writeBack(scene);
    }

    auto created = OffscreenRenderer::create(width, height);
    if (!created) {
        std::fprintf(stderr, "render_bench: %s\n", created.error().c_str());
        return 1;
    }
    OffscreenRenderer& headless = **created;
    FrameInput input;
    input.scene = &scene;
    input.world = world ? &*world : nullptr;
    Result<OverlaySet> chosen = parseOverlayList(overlays);
    if (!chosen) {
        std::fprintf(stderr, "render_bench: %s\n", chosen.error().c_str());
        return 2;
    }
    input.overlays = *chosen;
    input.camera = level.empty() ? fitCamera(scene, width, height) : sceneCamera(scene, width, height);
    input.trails = &trails;
    input.caption = "render_bench  |  " + std::to_string(bodies) + " bodies  |  " + overlays;
    if (!level.empty()) input.caption.clear();  // as the editor's viewport

    // Warm-up: llvmpipe compiles each shader variant on first use.
    Image image = headless.capture(input);
    double buildMs = 0, buildCpuMs = 0, glMs = 0, submitMs = 0, readMs = 0, best = 1e300;
    std::size_t instances = 0;
    int calls = 0;
    const double cpu0 = processCpuMs();
    for (int f = 0; f < frames; ++f) {
        const auto t0 = std::chrono::steady_clock::now();
        const double build0 = cpuMs(CLOCK_THREAD_CPUTIME_ID);
        DrawData data = buildDrawData(input, width, height, options);
        buildCpuMs += cpuMs(CLOCK_THREAD_CPUTIME_ID) - build0;
        const auto t1 = std::chrono::steady_clock::now();
        headless.renderer().draw(data);
        const auto tSubmit = std::chrono::steady_clock::now();
        headless.renderer().finish();
        const auto t15 = std::chrono::steady_clock::now();
        image = headless.renderer().readPixels(width, height);
        const auto t2 = std::chrono::steady_clock::now();
        buildMs += ms(t1 - t0);
        glMs += ms(t2 - t1);
        readMs += ms(t2 - t15);
        submitMs += ms(tSubmit - t1);
        best = std::min(best, ms(t2 - t0));
        instances = data.instanceCount();
        if (f == 0 && batches)
            for (const Batch& b : data.batches) std::printf("  batch: kind %d, plain %d, %zu instances\n", int(b.kind), int(b.plain), b.count());
        calls = headless.renderer().lastDrawCalls();
    }
    const double allCpuMs = (processCpuMs() - cpu0) / frames;
    const auto e0 = std::chrono::steady_clock::now();
    const std::string png = encodePng(image);
    const double encodeMs = ms(std::chrono::steady_clock::now() - e0);
    if (!out.empty()) {
        if (Result<void> w = writeFileAtomically(out, png); !w) std::fprintf(stderr, "%s\n", w.error().c_str());
    }
    std::printf("render_bench: %d bodies, %dx%d, overlays %s, %s\n", bodies, width, height, overlays.c_str(),
                headless.renderer().describeContext().c_str());
    std::printf("  %zu instances in %d draw calls\n", instances, calls);
    std::printf("  frame: %.1f ms mean (build %.1f ms CPU + GL draw/readback %.1f ms), best %.1f ms, over %d frames\n",
                (buildMs + glMs) / frames, buildMs / frames, glMs / frames, best, frames);
    std::printf("  of which submit (this thread: vertices, triangle setup, binning): %.1f ms, read back: %.1f ms\n",
                submitMs / frames, readMs / frames);
    std::printf("  CPU time of all threads: %.1f ms a frame, of the build: %.2f ms\n", allCpuMs, buildCpuMs / frames);
    std::printf("  PNG encode (not in the frame time): %.1f ms\n", encodeMs);
    std::printf("  target < 100 ms/frame: %s\n", (buildMs + glMs) / frames < 100.0 ? "met" : "NOT met");
    return 0;
}
