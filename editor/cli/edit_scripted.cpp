// `stepwise edit --script/--screenshot`: the editor headless, drawn through
// OSMesa, its input replayed from a script file through the same handlers a
// person's input goes through (docs/editor.md, "Scripted, headless").

#include "cli/cli_common.hpp"
#include "cli/commands.hpp"
#include "ui/edit_run.hpp"

#include "app/scene_edit.hpp"
#include "app/script.hpp"
#include "app/script_actions.hpp"
#include "image.hpp"
#include "offscreen.hpp"
#include "ui/session.hpp"

#include "stepwise/scene_io.hpp"

#include <GL/osmesa.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <sstream>

namespace stepwise::cli {

using ui::EditOptions;
using ui::FrameTimes;
using ui::kFrameSeconds;
using ui::writeDebugState;

namespace {

using editor::InputEvent;

/// The headless runner's side of the script actions: frames, panels, pixels.
class HeadlessHost final : public editor::ScriptHost {
public:
    HeadlessHost(ui::Session& session, std::function<void()> frame, int width, int height)
        : session_(session), frame_(std::move(frame)), width_(width), height_(height) {}
    void frame() override { frame_(); }
    bool showWindow(const std::string& name, bool on) override {
        ui::UiState& u = session_.ui();
        bool* flag = name == "inspector" ? &u.showInspector : name == "world" ? &u.showWorld
                   : name == "tools" ? &u.showTools : name == "entities" ? &u.showEntities
                   : name == "debug" ? &u.showDebug : name == "help" ? &u.showHelp : nullptr;
        if (!flag) return false;
        *flag = on;
        return true;
    }
    bool showDebugTab(const std::string& name) override {
        static const char* tabs[] = {"contacts", "plots", "profile", "history"};
        const auto it = std::find(std::begin(tabs), std::end(tabs), name);
        if (it == std::end(tabs)) return false;
        session_.ui().debugTab = int(it - std::begin(tabs));
        return true;
    }
    Result<void> screenshot(const std::string& path) override {
        const render::Image image = session_.capture(width_, height_);
        return writeFileAtomically(path, render::encodePng(image));
    }
    void reportError(const std::string& message) override { cli::reportError(message); }

private:
    ui::Session& session_;
    std::function<void()> frame_;
    int width_, height_;
};

void* osmesaProc(const char* name) { return reinterpret_cast<void*>(OSMesaGetProcAddress(name)); }

} // namespace

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
        // Every output before the first frame: writable (the saver's own
        // check, so a read-only or missing target is refused up front),
        // not an input, not another output.
        if (Result<void> checked = checkOutputs(inputs, outputs); !checked) {
            reportOutputProblem(checked.failure());
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
        ed.doc.reset(editor::benchScene(o.benchBodies));
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
    HeadlessHost host(session, frame, width, height);
    int status = kExitOk;
    for (const editor::ScriptCommand& c : commands) {
        using K = editor::ScriptCommand::Kind;
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
            // A whole keypress lets go of its modifiers too: a held ctrl
            // makes ImGui drop the characters of a following `text` line
            // (after ctrl+shift+s, Save as would keep its suggestion).
            if (c.kind == K::Key) pressMods(c.mods, false);
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
        case K::Action:
            if (!editor::runScriptAction(ed, host, c, o.script)) status = kExitBadInput;
            break;
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

} // namespace stepwise::cli
