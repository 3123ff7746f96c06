// stepwise edit [LEVEL]: the editor in an SDL2 window (OpenGL 3.3 core), or
// headless with --script/--screenshot: the same Session drawn through OSMesa,
// input replayed from a script file through the same handlers.

#include "cli/cli_common.hpp"
#include "cli/commands.hpp"

#include "app/scene_edit.hpp"
#include "app/script.hpp"
#include "render/image.hpp"
#include "render/offscreen.hpp"
#include "ui/session.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"

#include <GL/osmesa.h>
#include <nlohmann/json.hpp>
#include <SDL.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <numeric>
#include <sstream>

namespace stepwise::cli {

namespace {

using editor::InputEvent;
using editor::Key;

struct EditOptions {
    std::string level;
    std::string script;
    std::string screenshot;
    std::string size = "1280x800";
    float fontSize = 0.0f;
    bool builtinFont = false;
    std::string configDir;
    int benchFrames = 0;
    int benchBodies = 0;
    std::string debugState;
    bool headless = false;
    bool showTimings = false;
    bool noVsync = false;
    std::string overlays;
};

constexpr double kFrameSeconds = 1.0 / 60.0;  // scripted frames: fixed, so runs are deterministic

bool parseSize(const std::string& text, int& w, int& h) {
    char x = 0, extra = 0;
    return std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) == 3 && (x == 'x' || x == 'X') && w >= 320 &&
           h >= 240 && w <= 8192 && h <= 8192;
}

/// A synthetic level for --bench-bodies: N circles (0.25 m, 1 kg) in a
/// box of three planes under gravity, jittered so they do not stack in
/// perfect columns. Named c0, c1, ... directly: generating 100,000 bodies
/// through the palette's one-at-a-time naming would be quadratic.
Scene benchScene(int bodies) {
    Scene s;
    s.view = View{{0.0, 10.0}, 30.0};
    const int columns = int(std::ceil(std::sqrt(double(bodies) * 1.6)));
    editor::addPlane(s, {0.0, 0.0}, {0.0, 1.0});
    editor::addPlane(s, {-0.3 * columns - 1.0, 0.0}, {1.0, 0.0});
    editor::addPlane(s, {0.3 * columns + 1.0, 0.0}, {-1.0, 0.0});
    std::uint32_t seed = 7u;
    for (int i = 0; i < bodies; ++i) {
        const int cx = i % columns, cy = i / columns;
        seed = seed * 1664525u + 1013904223u;
        const double jitter = (double(seed >> 8) / double(1u << 24) - 0.5) * 0.05;
        const Entity e = s.registry.create();
        s.registry.emplace(e, Name{"c" + std::to_string(i)});
        s.registry.emplace(e, Position{{-0.3 * columns + 0.6 * cx + jitter + 0.3, 0.5 + 0.6 * cy}});
        s.registry.emplace(e, Velocity{{jitter * 20.0, 0.0}});
        s.registry.emplace(e, Mass{1.0});
        s.registry.emplace(e, Radius{0.25});
        s.registry.emplace(e, Color{Rgb{0.3 + 0.6 * double(cx) / columns, 0.5, 0.9 - 0.5 * double(cy % 20) / 20.0}});
    }
    return s;
}

void writeDebugState(const std::string& path, ui::Session& session, std::uint64_t frame) {
    editor::Editor& ed = session.editor();
    std::ostringstream out;
    out.precision(17);
    const char* mode = ed.sim.state() == editor::SimState::Playing ? "playing"
                       : ed.sim.state() == editor::SimState::Paused ? "paused" : "editing";
    const ImVec2 p = session.viewportPos(), z = session.viewportSize();
    out << "{\n  \"frame\": " << frame << ",\n  \"mode\": \"" << mode << "\",\n  \"time\": " << ed.doc.scene.world.time
        << ",\n  \"steps\": " << ed.sim.steps() << ",\n  \"entities\": " << ed.doc.scene.registry.size()
        << ",\n  \"dirty\": " << (ed.dirty() ? "true" : "false") << ",\n  \"viewport\": [" << p.x << ", " << p.y << ", "
        << z.x << ", " << z.y << "],\n  \"camera\": [" << ed.view.camera.center.x << ", " << ed.view.camera.center.y
        << ", " << ed.view.camera.zoom << "],\n  \"selection\": " << ed.selection.size();
    const ui::Session::DialogState d = session.dialogState();
    out << ",\n  \"modal\": " << nlohmann::json(d.modal).dump() << ",\n  \"status\": " << nlohmann::json(d.status).dump()
        << ",\n  \"open_folder\": " << nlohmann::json(d.openFolder).dump() << ",\n  \"open_files\": " << d.openFiles
        << ",\n  \"save_as_suggestion\": " << nlohmann::json(d.saveAsSuggestion).dump() << ",\n  \"positions\": [";
    int n = 0;
    for (Entity e : ed.doc.scene.registry.entities()) {
        const Position* pos = ed.doc.scene.registry.tryGet<Position>(e);
        if (!pos || ed.doc.scene.registry.has<Spring>(e)) continue;
        out << (n ? ", " : "") << "[" << pos->value.x << ", " << pos->value.y << "]";
        if (++n == 64) break;
    }
    out << "]\n}\n";
    (void)writeFileAtomically(path, out.str());
}

struct FrameTimes {
    std::vector<double> ms;
    ui::UiState::FrameParts sum;  ///< the parts summed over the recorded frames
    ui::UiState::FrameParts last; ///< the last recorded frame's parts

    void add(double frameMs, const ui::UiState::FrameParts& parts) {
        ms.push_back(frameMs);
        sum.uiMs += parts.uiMs;
        sum.stepMs += parts.stepMs;
        sum.sceneMs += parts.sceneMs;
        sum.drawUiMs += parts.drawUiMs;
        sum.presentMs += parts.presentMs;
        sum.steps += parts.steps;
        last = parts;
    }
    void report(const char* what, std::size_t bodies) const {
        if (ms.empty()) return;
        std::vector<double> sorted = ms;
        std::sort(sorted.begin(), sorted.end());
        const double n = double(sorted.size());
        const double mean = std::accumulate(sorted.begin(), sorted.end(), 0.0) / n;
        std::printf("edit bench (%s): %zu entities, %zu frames: mean %.2f ms, median %.2f ms, p95 %.2f ms, max %.2f ms "
                    "(%.1f fps at the mean)\n",
                    what, bodies, sorted.size(), mean, sorted[sorted.size() / 2], sorted[sorted.size() * 95 / 100],
                    sorted.back(), 1000.0 / mean);
        // Where a frame goes. "present" is the previous frame's buffer
        // swap (Session::frame): waiting for llvmpipe to finish drawing it,
        // then (under Xvfb) the copy to the X server. The rest is events.
        const double parts = (sum.uiMs + sum.stepMs + sum.sceneMs + sum.drawUiMs + sum.presentMs) / n;
        std::printf("  per frame: ui build %.2f ms, physics %.2f ms (%.2f steps), viewport render %.2f ms, "
                    "ui draw %.2f ms, present %.2f ms, rest %.2f ms\n",
                    sum.uiMs / n, sum.stepMs / n, double(sum.steps) / n, sum.sceneMs / n, sum.drawUiMs / n,
                    sum.presentMs / n, std::max(0.0, mean - parts));
        std::printf("  viewport, last frame: %zu instances in %d draw calls\n", last.instances, last.drawCalls);
    }
};

// ---- headless scripted mode ----------------------------------------------------------

void* osmesaProc(const char* name) { return reinterpret_cast<void*>(OSMesaGetProcAddress(name)); }

int runScripted(const EditOptions& o, int width, int height) {
    std::vector<editor::ScriptCommand> commands;
    if (!o.script.empty()) {
        std::ifstream in(o.script, std::ios::binary);
        if (!in) {
            reportError("--script: cannot read " + o.script);
            return kExitBadInput;
        }
        std::stringstream text;
        text << in.rdbuf();
        Result<std::vector<editor::ScriptCommand>> parsed = editor::parseScript(text.str(), o.script);
        if (!parsed) {
            reportError(parsed.error());
            return kExitBadInput;
        }
        commands = std::move(*parsed);
    }
    {
        std::vector<OutputFile> outputs;
        if (!o.screenshot.empty()) outputs.push_back({"--screenshot", o.screenshot});
        if (!o.debugState.empty()) outputs.push_back({"--debug-state", o.debugState});
        std::vector<std::string> inputs;
        if (!o.level.empty()) inputs.push_back(o.level);
        if (!o.script.empty()) inputs.push_back(o.script);
        if (std::string problem = checkOutputs(inputs, outputs); !problem.empty() && problem.rfind("stepwise: error: ", 0) == 0) {
            std::cerr << problem << "\n";
            return kExitBadInput;
        }
    }
    if (!o.screenshot.empty()) {
        const std::filesystem::path parent = std::filesystem::path(o.screenshot).parent_path();
        std::error_code ec;
        if (!parent.empty() && !std::filesystem::is_directory(parent, ec)) {
            reportError("--screenshot: folder " + parent.string() + " does not exist");
            return kExitBadInput;
        }
    }
    // The OSMesa context (and the renderer it makes, unused here) stays
    // current for the whole run; the session loads its own entry points.
    Result<std::unique_ptr<render::OffscreenRenderer>> context = render::OffscreenRenderer::create(width, height);
    if (!context) {
        reportError(context.error());
        return kExitFailure;
    }
    ui::SessionOptions so;
    so.fontSize = o.fontSize;
    so.builtinFont = o.builtinFont;
    so.persist = false;
    so.deterministic = !o.showTimings;
    if (!o.configDir.empty()) so.configDir = o.configDir;
    Result<std::unique_ptr<ui::Session>> created = ui::Session::create(osmesaProc, so);
    if (!created) {
        reportError(created.error());
        return kExitFailure;
    }
    ui::Session& session = **created;
    editor::Editor& ed = session.editor();
    if (!o.configDir.empty()) ed.configDir = o.configDir;
    ed.autosaveSeconds = 1e300;  // no autosave in scripted runs
    bool badLevel = false;
    if (o.benchBodies > 0) {
        ed.doc.reset(benchScene(o.benchBodies));
        ed.fitView();
    } else if (!session.openAtStart(o.level)) {
        badLevel = true;
        std::cerr << "stepwise: error: " << ed.errorModal << "\n";
    }

    if (!o.overlays.empty()) ed.overlays = render::parseOverlayList(o.overlays).value();
    std::uint64_t frameNo = 0;
    auto frame = [&] {
        session.frame(width, height, kFrameSeconds);
        ++frameNo;
        if (!o.debugState.empty()) writeDebugState(o.debugState, session, frameNo);
    };
    frame();  // lay the panels out once so the viewport rectangle is known
    auto toWindow = [&](const editor::ScriptPoint& p) -> Vec2 {
        if (!p.world) return p.value;
        const Vec2 px = ed.view.toPixels(p.value);
        return {session.viewportPos().x + px.x, session.viewportPos().y + px.y};
    };
    auto event = [](InputEvent::Type t, Vec2 at, editor::MouseButton b = editor::MouseButton::Left) {
        InputEvent e;
        e.type = t;
        e.x = at.x;
        e.y = at.y;
        e.button = b;
        return e;
    };
    auto findEntity = [&](const std::string& name) { return editor::findByName(ed.doc.scene.registry, name); };
    // Click and drag lines with shift/ctrl hold the modifiers around the
    // mouse events, as a person holding the key would.
    auto pressMods = [&](std::uint8_t mods, bool down) {
        if (!mods) return;
        InputEvent k;
        k.type = down ? InputEvent::Type::KeyDown : InputEvent::Type::KeyUp;
        k.mods = down ? mods : std::uint8_t(0);
        session.queue(k);
        if (!down) frame();
    };
    int status = kExitOk;
    for (const editor::ScriptCommand& c : commands) {
        using K = editor::ScriptCommand::Kind;
        auto failLine = [&](const std::string& what) {
            reportError(o.script + ":" + std::to_string(c.line) + ": " + what);
            status = kExitBadInput;
        };
        switch (c.kind) {
        case K::Key:
        case K::KeyDown:
        case K::KeyUp: {
            InputEvent e;
            e.key = c.key;
            e.mods = c.mods;
            if (c.kind != K::KeyUp) {
                e.type = InputEvent::Type::KeyDown;
                session.queue(e);
                frame();
            }
            if (c.kind != K::KeyDown) {
                e.type = InputEvent::Type::KeyUp;
                session.queue(e);
                frame();
            }
            break;
        }
        case K::Move:
            session.queue(event(InputEvent::Type::MouseMove, toWindow(c.a)));
            frame();
            break;
        case K::Click: {
            const Vec2 at = toWindow(c.a);
            pressMods(c.mods, true);
            session.queue(event(InputEvent::Type::MouseMove, at));
            frame();
            session.queue(event(InputEvent::Type::MouseDown, at, c.button));
            frame();
            session.queue(event(InputEvent::Type::MouseUp, at, c.button));
            frame();
            pressMods(c.mods, false);
            break;
        }
        case K::Drag: {
            const Vec2 a = toWindow(c.a), b = toWindow(c.b);
            pressMods(c.mods, true);
            session.queue(event(InputEvent::Type::MouseMove, a));
            frame();
            session.queue(event(InputEvent::Type::MouseDown, a, c.button));
            frame();
            for (int i = 1; i <= c.count; ++i) {
                session.queue(event(InputEvent::Type::MouseMove, a + (b - a) * (double(i) / c.count), c.button));
                frame();
            }
            session.queue(event(InputEvent::Type::MouseUp, b, c.button));
            frame();
            pressMods(c.mods, false);
            break;
        }
        case K::Wheel: {
            if (c.hasPoint) {
                session.queue(event(InputEvent::Type::MouseMove, toWindow(c.a)));
                frame();
            }
            InputEvent e;
            e.type = InputEvent::Type::Wheel;
            e.wheel = c.number;
            const ImVec2 mp = ImGui::GetIO().MousePos;
            e.x = mp.x;
            e.y = mp.y;
            session.queue(e);
            frame();
            break;
        }
        case K::Text: {
            InputEvent e;
            e.type = InputEvent::Type::Text;
            e.text = c.text;
            session.queue(e);
            frame();
            break;
        }
        case K::Wait:
            for (int i = 0; i < c.count; ++i) frame();
            break;
        case K::Action: {
            const std::string& a = c.text;
            // A command that fails in the editor opens an error dialog; in a
            // script it stops the run with the dialog's text on stderr and
            // exit 2, as a bad line does (open, saveas and savestate of a
            // missing path exited 0 with nothing on stderr).
            const std::string modalBefore = ed.errorModal;
            auto failed = [&](const char* what) {
                std::string why = ed.errorModal != modalBefore ? ed.errorModal : std::string();
                for (char& ch : why)
                    if (ch == '\n') ch = ' ';
                failLine(std::string(what) + (why.empty() ? "" : ": " + why));
            };
            const std::vector<std::string>& args = c.args;
            auto onOff = [&](const std::string& v, bool& out) {
                if (v == "on") out = true;
                else if (v == "off") out = false;
                else return false;
                return true;
            };
            bool on = false;
            if (a == "play") {
                if (ed.sim.state() != editor::SimState::Playing) ed.togglePlay();
            } else if (a == "pause") {
                if (ed.sim.state() == editor::SimState::Playing) ed.togglePlay();
            } else if (a == "step") {
                for (int i = 0; i < c.count && status == kExitOk; ++i) {
                    ed.stepForward();
                    // A diverged step, or a level that cannot be simulated.
                    if (ed.sim.diverged() || ed.sim.message().rfind("cannot simulate", 0) == 0)
                        failLine("step " + std::to_string(i + 1) + " of " + std::to_string(c.count) + ": " +
                                 ed.sim.message());
                }
            } else if (a == "stepback") {
                for (int i = 0; i < c.count; ++i) ed.stepBack();
            } else if (a == "reset") ed.resetSimulation();
            else if (a == "undo") ed.undo();
            else if (a == "redo") ed.redo();
            else if (a == "fit") ed.fitView();
            else if (a == "new") ed.newDocument();
            else if (a == "open") {
                if (!ed.open(args[0])) failed("open failed");
            } else if (a == "save") {
                if (ed.doc.path.empty()) failLine("save: the level has no file yet; use saveas PATH");
                else if (!ed.save()) failed("save failed");
            } else if (a == "saveas") {
                if (!ed.saveAs(args[0])) failed("saveas failed");
            } else if (a == "savestate") {
                if (!ed.saveStateAs(args[0])) failed("savestate failed");
            }
            else if (a == "tool") {
                bool found = false;
                static const char* names[] = {"select", "rotate", "circle", "box", "plane", "spring", "attractor", "boids", "joint", "polygon"};
                static_assert(std::size(names) == std::size_t(editor::Tool::Count), "a name per tool");
                for (int t = 0; t < int(editor::Tool::Count); ++t)
                    if (args[0] == names[t]) {
                        ed.tool = editor::Tool(t);
                        found = true;
                    }
                if (!found) failLine("tool: unknown tool \"" + args[0] + "\"");
            } else if (a == "select") {
                std::vector<Entity> sel;
                if (args[0] == "all") sel = ed.doc.scene.registry.entities();
                else if (args[0] != "none")
                    for (const std::string& n : args) {
                        const Entity e = findEntity(n);
                        if (e.isNull()) failLine("select: no entity named \"" + n + "\"");
                        else sel.push_back(e);
                    }
                ed.select(sel);
            } else if (a == "overlay") {
                const auto& names = render::overlayNames();
                const auto it = std::find_if(names.begin(), names.end(), [&](const auto& p) { return p.first == args[0]; });
                if (it == names.end() || !onOff(args[1], on)) failLine("overlay: expected a known overlay and on|off");
                else ed.overlays.bits = on ? ed.overlays.bits | std::uint32_t(it->second) : ed.overlays.bits & ~std::uint32_t(it->second);
            } else if (a == "system") {
                if (!editor::Simulation::canDisable(args[0]))
                    failLine("system: unknown system \"" + args[0] + "\" (gravity, drag, springs, attractors, boids, collisions)");
                else if (!onOff(args[1], on)) failLine("system: expected on|off");
                else {
                    if (on) ed.sim.disabledSystems.erase(args[0]);
                    else ed.sim.disabledSystems.insert(args[0]);
                    ed.sim.sceneChanged();
                }
            } else if (a == "snap") {
                if (!onOff(args[0], ed.snap)) failLine("snap: expected on|off");
            } else if (a == "timescale") ed.sim.timeScale = c.number;
            else if (a == "breakon") {
                const Entity e = args[0] == "none" ? Entity{} : findEntity(args[0]);
                if (args[0] != "none" && e.isNull()) failLine("breakon: no entity named \"" + args[0] + "\"");
                else ed.sim.breakOnContact = e;
            }
            else if (a == "window") {
                ui::UiState& u = session.ui();
                bool* flag = args[0] == "inspector" ? &u.showInspector : args[0] == "world" ? &u.showWorld
                           : args[0] == "tools" ? &u.showTools : args[0] == "entities" ? &u.showEntities
                           : args[0] == "debug" ? &u.showDebug : args[0] == "help" ? &u.showHelp : nullptr;
                if (!flag || !onOff(args[1], *flag)) failLine("window: expected inspector|world|tools|entities|debug|help on|off");
            } else if (a == "tab") {
                static const char* tabs[] = {"contacts", "plots", "profile", "history"};
                const auto it = std::find(std::begin(tabs), std::end(tabs), args[0]);
                if (it == std::end(tabs)) failLine("tab: expected contacts|plots|profile|history");
                else session.ui().debugTab = int(it - std::begin(tabs));
            } else if (a == "screenshot") {
                frame();
                const render::Image image = session.capture(width, height);
                if (Result<void> w = writeFileAtomically(args[0], render::encodePng(image)); !w) failLine(w.error());
                break;
            }
            // Any other action that opened an error dialog (play on a level
            // that cannot be simulated, a step that diverged) failed too.
            if (status == kExitOk && ed.errorModal != modalBefore && !ed.errorModal.empty()) failed(a.c_str());
            if (status == kExitOk) frame();
            break;
        }
        }
        if (status != kExitOk) return status;
    }
    // Two settling frames: popups opened by the last command appear.
    frame();
    frame();
    if (o.benchFrames > 0) {
        if (ed.sim.state() != editor::SimState::Playing) ed.togglePlay();
        FrameTimes times;
        for (int i = 0; i < o.benchFrames; ++i) {
            const auto t0 = std::chrono::steady_clock::now();
            session.frame(width, height, kFrameSeconds);
            session.capture(1, 1);  // wait for the GPU, as a swap would
            times.add(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count(), session.ui().lastFrame);
        }
        times.report("OSMesa, headless", ed.doc.scene.registry.size());
    }
    if (!o.screenshot.empty()) {
        const render::Image image = session.capture(width, height);
        if (Result<void> w = writeFileAtomically(o.screenshot, render::encodePng(image)); !w) {
            reportError("--screenshot: " + w.error());
            return kExitBadInput;
        }
    }
    return badLevel ? kExitBadInput : kExitOk;
}

// ---- SDL window --------------------------------------------------------------------------

Key keyFromSdl(SDL_Keycode k) {
    if (k >= SDLK_a && k <= SDLK_z) return Key(std::uint16_t(Key::A) + std::uint16_t(k - SDLK_a));
    if (k >= SDLK_0 && k <= SDLK_9) return Key(std::uint16_t(Key::Num0) + std::uint16_t(k - SDLK_0));
    switch (k) {
    case SDLK_SPACE: return Key::Space;
    case SDLK_LEFT: return Key::Left;
    case SDLK_RIGHT: return Key::Right;
    case SDLK_UP: return Key::Up;
    case SDLK_DOWN: return Key::Down;
    case SDLK_DELETE: return Key::Delete;
    case SDLK_BACKSPACE: return Key::Backspace;
    case SDLK_ESCAPE: return Key::Escape;
    case SDLK_RETURN:
    case SDLK_KP_ENTER: return Key::Enter;
    case SDLK_TAB: return Key::Tab;
    case SDLK_HOME: return Key::Home;
    case SDLK_END: return Key::End;
    case SDLK_PAGEUP: return Key::PageUp;
    case SDLK_PAGEDOWN: return Key::PageDown;
    case SDLK_F1: return Key::F1;
    case SDLK_F2: return Key::F2;
    case SDLK_F3: return Key::F3;
    case SDLK_F4: return Key::F4;
    case SDLK_F5: return Key::F5;
    default: return Key::None;
    }
}

std::uint8_t modsFromSdl(Uint16 m) {
    std::uint8_t out = 0;
    if (m & KMOD_CTRL) out |= editor::kModCtrl;
    if (m & KMOD_SHIFT) out |= editor::kModShift;
    if (m & KMOD_ALT) out |= editor::kModAlt;
    return out;
}

int runWindow(const EditOptions& o, int width, int height) {
    if (SDL_Init(SDL_INIT_VIDEO | SDL_INIT_TIMER) != 0) {
        reportError(std::string("cannot start SDL video (is there a display? use --script/--screenshot for headless "
                                "runs): ") + SDL_GetError());
        return kExitFailure;
    }
    // With no display, Debian's SDL 2.26 does not fail: it falls back to its
    // invisible "offscreen" driver, and the editor would run a window nobody
    // can see until it is killed. Such a driver is honoured only when asked
    // for by name (SDL_VIDEODRIVER).
    const char* driver = SDL_GetCurrentVideoDriver();
    if (driver && (!std::strcmp(driver, "offscreen") || !std::strcmp(driver, "dummy")) && !SDL_getenv("SDL_VIDEODRIVER")) {
        reportError(std::string("cannot start SDL video (is there a display? use --script/--screenshot for headless "
                                "runs): SDL found no display, only its \"") + driver + "\" driver");
        SDL_Quit();
        return kExitFailure;
    }
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_PROFILE_MASK, SDL_GL_CONTEXT_PROFILE_CORE);
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MAJOR_VERSION, 3);
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MINOR_VERSION, 3);
    SDL_GL_SetAttribute(SDL_GL_DOUBLEBUFFER, 1);
    SDL_GL_SetAttribute(SDL_GL_DEPTH_SIZE, 0);
    SDL_Window* window = SDL_CreateWindow("Stepwise", SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED, width, height,
                                          SDL_WINDOW_OPENGL | SDL_WINDOW_RESIZABLE);
    if (!window) {
        reportError(std::string("cannot open a window: ") + SDL_GetError());
        SDL_Quit();
        return kExitFailure;
    }
    SDL_GLContext context = SDL_GL_CreateContext(window);
    if (!context) {
        reportError(std::string("cannot create an OpenGL 3.3 core context: ") + SDL_GetError());
        SDL_DestroyWindow(window);
        SDL_Quit();
        return kExitFailure;
    }
    SDL_GL_MakeCurrent(window, context);
    SDL_GL_SetSwapInterval(o.noVsync || o.benchFrames > 0 ? 0 : 1);
    float dpi = 96.0f;
    if (SDL_GetDisplayDPI(0, nullptr, &dpi, nullptr) != 0 || !(dpi > 0)) dpi = 96.0f;
    ui::SessionOptions so;
    so.fontSize = o.fontSize;
    so.builtinFont = o.builtinFont;
    so.dpiScale = std::clamp(dpi / 96.0f, 1.0f, 3.0f);
    if (!o.configDir.empty()) so.configDir = o.configDir;
    int code = kExitOk;
    {
        Result<std::unique_ptr<ui::Session>> created =
            ui::Session::create([](const char* n) { return SDL_GL_GetProcAddress(n); }, so);
        if (!created) {
            reportError(created.error());
            code = kExitFailure;
        } else {
            ui::Session& session = **created;
            editor::Editor& ed = session.editor();
            if (o.benchBodies > 0) {
                ed.doc.reset(benchScene(o.benchBodies));
                ed.fitView();
            } else {
                (void)session.openAtStart(o.level);  // a bad level: the error modal shows the loader's message
            }
            if (!o.overlays.empty()) ed.overlays = render::parseOverlayList(o.overlays).value();
            SDL_StartTextInput();
            auto last = std::chrono::steady_clock::now();
            const auto start = last;
            std::uint64_t frameNo = 0;
            FrameTimes times;
            bool benchPlaying = false;
            // A frame is drawn, then shown from inside the next one (see
            // Session::frame), or before the loop idles.
            bool drawnNotShown = false;
            const auto presentPrevious = [&] {
                if (drawnNotShown) SDL_GL_SwapWindow(window);
                drawnNotShown = false;
            };
            while (!session.wantsQuit()) {
                SDL_Event ev;
                while (SDL_PollEvent(&ev)) {
                    InputEvent e;
                    switch (ev.type) {
                    case SDL_QUIT: ed.request(editor::PendingAction::Quit); break;
                    case SDL_KEYDOWN:
                    case SDL_KEYUP:
                        e.type = ev.type == SDL_KEYDOWN ? InputEvent::Type::KeyDown : InputEvent::Type::KeyUp;
                        e.key = keyFromSdl(ev.key.keysym.sym);
                        e.mods = modsFromSdl(ev.key.keysym.mod);
                        // Modifier keys themselves update the held modifiers.
                        session.queue(e);
                        break;
                    case SDL_TEXTINPUT:
                        e.type = InputEvent::Type::Text;
                        e.text = ev.text.text;
                        session.queue(e);
                        break;
                    case SDL_MOUSEMOTION:
                        e.type = InputEvent::Type::MouseMove;
                        e.x = ev.motion.x;
                        e.y = ev.motion.y;
                        session.queue(e);
                        break;
                    case SDL_MOUSEBUTTONDOWN:
                    case SDL_MOUSEBUTTONUP:
                        if (ev.button.button > 3) break;
                        e.type = ev.type == SDL_MOUSEBUTTONDOWN ? InputEvent::Type::MouseDown : InputEvent::Type::MouseUp;
                        e.button = ev.button.button == SDL_BUTTON_LEFT ? editor::MouseButton::Left
                                   : ev.button.button == SDL_BUTTON_RIGHT ? editor::MouseButton::Right
                                                                          : editor::MouseButton::Middle;
                        e.x = ev.button.x;
                        e.y = ev.button.y;
                        e.mods = modsFromSdl(Uint16(SDL_GetModState()));
                        session.queue(e);
                        break;
                    case SDL_MOUSEWHEEL: {
                        int mx = 0, my = 0;
                        SDL_GetMouseState(&mx, &my);
                        e.type = InputEvent::Type::Wheel;
                        e.wheel = ev.wheel.y;
                        e.x = mx;
                        e.y = my;
                        session.queue(e);
                        break;
                    }
                    default: break;
                    }
                }
                int w = width, h = height;
                SDL_GL_GetDrawableSize(window, &w, &h);
                const auto now = std::chrono::steady_clock::now();
                // Real time, clamped: a stall (window drag, debugger) must
                // not turn into a burst of steps.
                const double seconds = std::clamp(std::chrono::duration<double>(now - last).count(), 0.0, 0.1);
                if (o.benchFrames > 0 && frameNo > 0)
                    times.add(1e3 * std::chrono::duration<double>(now - last).count(), session.ui().lastFrame);
                last = now;
                if (o.benchFrames > 0 && !benchPlaying) {
                    ed.togglePlay();
                    benchPlaying = true;
                }
                session.frame(w, h, seconds, presentPrevious);
                drawnNotShown = true;
                ++frameNo;
                ed.tickAutosave(std::chrono::duration<double>(now - start).count());
                if (!o.debugState.empty() && frameNo % 10 == 0) writeDebugState(o.debugState, session, frameNo);
                if (o.benchFrames > 0 && int(times.ms.size()) >= o.benchFrames) break;
                // While a modal waits on the user, nothing moves: idle a little.
                if (!session.hasQueuedEvents() && ed.sim.state() != editor::SimState::Playing && o.benchFrames == 0) {
                    presentPrevious();  // idle: show the last frame now, not after the wait
                    SDL_WaitEventTimeout(nullptr, 15);
                }
            }
            if (o.benchFrames > 0) times.report("SDL window, swap included", ed.doc.scene.registry.size());
            session.saveSettings();
            if (!ed.dirty()) ed.discardRecovery();
        }
    }
    SDL_GL_DeleteContext(context);
    SDL_DestroyWindow(window);
    SDL_Quit();
    return code;
}

} // namespace

void addEditCommand(CLI::App& app, int& exitCode) {
    auto o = std::make_shared<EditOptions>();
    CLI::App* cmd = app.add_subcommand("edit", "Open the editor (SDL2 window; headless with --script/--screenshot)");
    cmd->add_option("level", o->level, "Level to open")->default_val("levels/default.json");
    cmd->add_option("--script", o->script, "Replay input from this file (headless, OSMesa); see docs/editor.md");
    cmd->add_option("--screenshot", o->screenshot, "Headless: write the whole editor as a PNG at the end");
    cmd->add_option("--size", o->size, "Window size WxH")->default_val("1280x800");
    cmd->add_option("--font-size", o->fontSize, "UI font size in pixels (default: 13 x display DPI / 96)")
        ->check(CLI::Range(8.0f, 48.0f));
    cmd->add_flag("--builtin-font", o->builtinFont, "Use ImGui's embedded font (the screenshot tests do)");
    cmd->add_option("--config", o->configDir, "Settings folder (default $XDG_CONFIG_HOME/stepwise)");
    cmd->add_option("--bench-frames", o->benchFrames, "Play and report the frame time over N frames")
        ->check(CLI::Range(1, 100000));
    cmd->add_option("--bench-bodies", o->benchBodies, "Benchmark a generated level of N circles instead of LEVEL")
        ->check(CLI::Range(1, 1000000));
    cmd->add_option("--debug-state", o->debugState, "Write the editor's state (mode, time, positions) to this JSON file")
        ->check(outputFileName());
    cmd->add_flag("--headless", o->headless, "Run through OSMesa without a window (implied by --script/--screenshot)");
    cmd->add_flag("--show-timings", o->showTimings, "Headless: show wall-clock timings (screenshots then differ run to run)");
    cmd->add_flag("--no-vsync", o->noVsync, "Window: do not wait for the display's refresh");
    cmd->add_option("--overlay", o->overlays, "Overlays to start with: velocity,force-field,...|all (default velocity,contacts)");
    cmd->callback([o, &exitCode] {
        int w = 0, h = 0;
        if (!parseSize(o->size, w, h)) {
            reportError("--size: expected WxH between 320x240 and 8192x8192, got \"" + o->size + "\"");
            exitCode = kExitBadInput;
            return;
        }
        if (Result<render::OverlaySet> ov = render::parseOverlayList(o->overlays); !ov) {
            reportError("--overlay: " + ov.error());
            exitCode = kExitBadInput;
            return;
        }
        // Started from another folder with no level named: the default level
        // beside the executable, not a "levels/default.json" that is not there.
        std::error_code ec;
        if (o->level == "levels/default.json" && !std::filesystem::exists(o->level, ec))
            o->level = (editor::findLevelsDirectory(editor::executableDirectory(), std::filesystem::current_path(ec)) /
                        "default.json")
                           .string();
        const bool headless = o->headless || !o->script.empty() || !o->screenshot.empty();
        exitCode = headless ? runScripted(*o, w, h) : runWindow(*o, w, h);
    });
}

} // namespace stepwise::cli
