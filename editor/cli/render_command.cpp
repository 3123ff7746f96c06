// stepwise render LEVEL --out FILE.png: headless screenshots through OSMesa
// (no display, no X server). Optionally steps the world first, records
// trails while stepping, and writes a numbered sequence (--frames/--every).

#include "cli/cli_common.hpp"
#include "cli/option_checks.hpp"
#include "cli/commands.hpp"

#include "offscreen.hpp"

#include "stepwise/components.hpp"
#include "stepwise/integrators.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>
#include <vector>

namespace stepwise::cli {

namespace {

struct RenderOptions {
    std::string level;
    long long steps = 0;
    std::optional<std::string> integrator;
    int width = 1280;
    int height = 720;
    std::string overlays;
    std::optional<std::string> camera;
    std::string out;
    int frames = 1;
    long long every = 1;
    std::string select;
    int trail = 48;
    bool noHud = false;
    bool noCaption = false;
};

/// "X,Y,ZOOM" -> Camera; the error names the argument.
Result<render::Camera> parseCamera(const std::string& text) {
    render::Camera cam;
    double v[3];
    char extra = 0;
    if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &extra) != 3 || !std::isfinite(v[0]) ||
        !std::isfinite(v[1]) || !std::isfinite(v[2]))
        return Error{"--camera: expected X,Y,ZOOM (metres, metres, pixels per metre at 720 px height), got \"" + text +
                     "\""};
    if (!(v[2] > 0.0)) {
        char zoom[32];
        std::snprintf(zoom, sizeof zoom, "%g", v[2]);  // "0", not to_string's "0.000000"
        return Error{"--camera: ZOOM must be > 0, got " + std::string(zoom)};
    }
    cam.center = {v[0], v[1]};
    cam.zoom = v[2];
    return cam;
}

/// FILE.png -> FILE-0007.png for frame 7 of a sequence.
std::string frameName(const std::string& out, int frame, int frames) {
    if (frames == 1) return out;
    std::filesystem::path p(out);
    char suffix[16];
    std::snprintf(suffix, sizeof suffix, "-%04d", frame);
    return (p.parent_path() / (p.stem().string() + suffix + p.extension().string())).string();
}

void progress(int done, int total) {
    const int width = 30;
    const int filled = total ? done * width / total : width;
    std::fprintf(stderr, "\r[%.*s%.*s] %d/%d frames", filled, "##############################", width - filled,
                 "                              ", done, total);
    if (done == total) std::fputc('\n', stderr);
    std::fflush(stderr);
}

std::string shortNumber(double v) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", v);
    return buffer;
}

int render(const RenderOptions& o) {
    // ---- arguments that CLI11 cannot check on its own ------------------
    Result<render::OverlaySet> overlays = render::parseOverlayList(o.overlays);
    if (!overlays) {
        reportError("--overlay: " + overlays.error());
        return kExitBadInput;
    }
    std::optional<render::Camera> camera;
    if (o.camera) {
        Result<render::Camera> parsed = parseCamera(*o.camera);
        if (!parsed) {
            reportError(parsed.error());
            return kExitBadInput;
        }
        camera = *parsed;
    }
    {
        // Fail before rendering anything when the folder is missing.
        const std::filesystem::path parent = std::filesystem::path(o.out).parent_path();
        std::error_code ec;
        if (!parent.empty() && !std::filesystem::is_directory(parent, ec)) {
            reportError("--out: folder " + parent.string() +
                        (std::filesystem::exists(parent, ec) ? " is not a folder" : " does not exist"));
            return kExitBadInput;
        }
    }
    // Before the level loads: a size past the limit costs nothing to refuse.
    if (std::optional<Error> size = render::OffscreenRenderer::sizeProblem(o.width, o.height)) {
        reportError("--width/--height: " + size->message);
        return kExitBadInput;
    }
    // The last frame's step count must fit in a long long.
    if (o.frames > 1 && o.steps > std::numeric_limits<long long>::max() - (long long)(o.frames - 1) * o.every) {
        reportError("--steps: " + std::to_string(o.steps) + " plus " + std::to_string(o.frames - 1) + " x --every " +
                    std::to_string(o.every) + " steps does not fit in a 64-bit count");
        return kExitBadInput;
    }

    std::optional<Scene> scene = loadLevelOrReport(o.level);
    if (!scene) return kExitBadInput;
    if (o.integrator) scene->world.integrator = *o.integrator;
    {
        // Every frame's file before any step: writable, not the level.
        std::vector<OutputFile> outputs;
        for (int frame = 0; frame < o.frames; ++frame) outputs.push_back({"--out", frameName(o.out, frame, o.frames)});
        if (Result<void> checked = checkOutputs({o.level}, outputs); !checked) {
            // A frame that cannot be written is named as --out's.
            if (checked.failure().kind == ErrorKind::Io) reportError("--out: " + checked.failure().message);
            else reportOutputProblem(checked.failure());
            return kExitBadInput;
        }
    }

    std::vector<Entity> selection;
    if (!o.select.empty()) {
        std::stringstream names(o.select);
        for (std::string name; std::getline(names, name, ',');) {
            bool found = false;
            for (Entity e : scene->registry.entities())
                if (const Name* n = scene->registry.tryGet<Name>(e); n && n->value == name) {
                    selection.push_back(e);
                    found = true;
                }
            if (!found) {
                reportError("--select: " + o.level + " has no entity named \"" + name + "\"");
                return kExitBadInput;
            }
        }
    }

    // ---- the world: needed to step, or for force/contact overlays -------
    const bool stepping = o.steps > 0 || o.frames > 1;
    std::optional<World> world;
    if (stepping || overlays->needsWorld()) {
        Result<World> built = World::build(*scene);
        if (built) {
            world.emplace(std::move(*built));
        } else if (stepping) {
            reportError(o.level + ": cannot simulate: " + built.error());
            return kExitBadInput;
        } else {
            // --steps 0 draws the scene as it is; overlays that need the
            // simulation say so in the legend.
            std::cerr << "stepwise: note: " << o.level << ": no World (" << built.error()
                      << "); force, net-force, force-field, contacts and joints overlays are skipped\n";
        }
    }

    Result<std::unique_ptr<render::OffscreenRenderer>> offscreen = render::OffscreenRenderer::create(o.width, o.height);
    if (!offscreen) {
        reportError(offscreen.error());
        // A size the user gave is bad input; a machine without the context is not.
        return offscreen.failure().kind == ErrorKind::BadInput ? kExitBadInput : kExitFailure;
    }
    render::OffscreenRenderer& headless = **offscreen;

    render::TrailRecorder trails(std::size_t(std::max(2, o.trail)));
    if (world) trails.record(*world); else trails.record(*scene);

    render::FrameInput input;
    input.scene = &*scene;
    input.world = world ? &*world : nullptr;
    input.overlays = *overlays;
    // Fixed for the whole sequence so the picture does not swim.
    input.camera = camera ? *camera : render::sceneCamera(*scene, o.width, o.height);
    input.selection = selection;
    input.trails = &trails;
    input.hud = !o.noHud;

    const bool tty = ::isatty(2) && o.frames > 1;
    // Each frame goes to a temporary next to its file; all are put in
    // place at the end, so a run that fails (exit 2 or 3) writes nothing.
    std::vector<StreamedFileWriter> written;
    written.reserve(std::size_t(o.frames));
    const std::string levelName = std::filesystem::path(o.level).filename().string();
    long long stepsTaken = 0;
    double renderMs = 0.0;
    std::size_t instances = 0;
    for (int frame = 0; frame < o.frames; ++frame) {
        const long long target = o.steps + (long long)frame * o.every;
        if (stepsTaken < target) {
            const AdvanceResult run = advance(*world, std::uint64_t(target - stepsTaken),
                                              {.afterStep = [&](std::uint64_t) {
                                              trails.record(*world);
                                              return true;
                                          }});
            stepsTaken += (long long)run.taken;
            if (run.divergence) {
                if (tty) std::fputc('\n', stderr);
                reportError(o.level + ": simulation diverged at " + run.divergence->message + " (integrator " +
                            world->settings().integrator + ") before frame " + std::to_string(frame) +
                            "; no frame written");
                return kExitDiverged;
            }
        }
        if (world) world->writeBack(*scene);
        input.caption = o.noCaption ? std::string()
                                    : levelName + "  |  t = " + shortNumber(scene->world.time) + " s  |  step " +
                                          std::to_string(stepsTaken) + "  |  " + scene->world.integrator;

        const auto start = std::chrono::steady_clock::now();
        render::DrawData drawn;
        const render::Image image = headless.capture(input, &drawn);
        renderMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        instances = drawn.instanceCount();
        // Later frames reuse the first frame's arrow references, so arrow
        // lengths compare across the sequence.
        input.scales = drawn.scales;

        const std::string path = frameName(o.out, frame, o.frames);
        Result<StreamedFileWriter> writer = StreamedFileWriter::open(path);
        Result<void> done = writer ? writer->write(render::encodePng(image)) : Result<void>(Error{writer.error()});
        if (done) done = writer->finish();
        if (!done) {
            if (tty) std::fputc('\n', stderr);
            reportError("--out: " + done.error());
            return kExitBadInput;
        }
        written.push_back(std::move(*writer));
        if (tty) progress(frame + 1, o.frames);
    }
    for (StreamedFileWriter& frameFile : written)
        if (Result<void> done = frameFile.commit(); !done) {
            reportError("--out: " + done.error());
            return kExitBadInput;
        }
    std::cout << "wrote " << (o.frames == 1 ? o.out : frameName(o.out, 0, o.frames) + " .. " +
                                                          frameName(o.out, o.frames - 1, o.frames))
              << " (" << o.width << "x" << o.height << ", " << stepsTaken << " steps, " << instances
              << " instances, " << shortNumber(renderMs / o.frames) << " ms/frame)\n";
    return kExitOk;
}

} // namespace

void addRenderCommand(CLI::App& app, int& exitCode) {
    auto o = std::make_shared<RenderOptions>();
    CLI::App* cmd = app.add_subcommand("render", "Render a level to PNG headlessly (OSMesa; no display needed)");
    cmd->add_option("LEVEL", o->level, "Level file (JSON)")->required();
    cmd->add_option("--out", o->out, "Output PNG (a sequence adds -0000, -0001, ... before the extension)")
        ->required()
        ->check(outputFileName());
    cmd->add_option("--steps", o->steps, "Steps to simulate before the (first) frame")
        ->check(wholeNumberAtLeastZero());
    cmd->add_option("--integrator", o->integrator, "Integrator (overrides world.integrator)")
        ->check(CLI::IsMember(std::vector<std::string>(integratorNames().begin(), integratorNames().end())));
    cmd->add_option("--width", o->width, "Image width, pixels")->check(CLI::Range(16, 16384));
    cmd->add_option("--height", o->height, "Image height, pixels")->check(CLI::Range(16, 16384));
    cmd->add_option("--overlay", o->overlays,
                    "Comma-separated overlays: velocity, velocity-field, force-field, force (applied: gravity, "
                    "springs, ...), net-force (m dv/dt over the last step, contacts included), contacts, aabb, "
                    "trails, joints, or all");
    cmd->add_option("--camera", o->camera,
                    "X,Y,ZOOM: centre in metres and pixels per metre at 720 px height (default: the level's "
                    "view, else fit the scene)");
    cmd->add_option("--frames", o->frames, "Number of frames to write")->check(CLI::Range(1, 100000));
    cmd->add_option("--every", o->every, "Steps between frames")->check(CLI::Range(1LL, 1000000000LL));
    cmd->add_option("--select", o->select, "Comma-separated entity names to highlight");
    cmd->add_option("--trail", o->trail, "Trail length, recorded steps")->check(CLI::Range(2, 100000));
    cmd->add_flag("--no-hud", o->noHud, "Omit the caption, scale bar and legend");
    cmd->add_flag("--no-caption", o->noCaption,
                  "Omit the caption only (the editor's viewport has none: tests compare the two)");
    cmd->callback([o, &exitCode] { exitCode = render(*o); });
}

} // namespace stepwise::cli
