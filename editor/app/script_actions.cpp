#include "app/script_actions.hpp"

#include "app/editor.hpp"
#include "app/scene_edit.hpp"

#include <algorithm>
#include <cstdint>

namespace stepwise::editor {

ScriptActionRun::ScriptActionRun(Editor& editor, ScriptHost& h, const ScriptCommand& command, std::string scriptName)
    : ed(editor), host(h), c(command), scriptName_(std::move(scriptName)), modalBefore_(editor.errorModal) {}

void ScriptActionRun::failLine(const std::string& what) {
    host.reportError(scriptName_ + ":" + std::to_string(c.line) + ": " + what);
    ok_ = false;
}

// A command that fails in the editor opens an error dialog; in a script it
// stops the run with the dialog's text on stderr and exit 2, as a bad line
// does (open, saveas and savestate of a missing path exited 0 with nothing
// on stderr).
void ScriptActionRun::failed(const char* what) {
    std::string why = ed.errorModal != modalBefore_ ? ed.errorModal : std::string();
    for (char& ch : why)
        if (ch == '\n') ch = ' ';
    failLine(std::string(what) + (why.empty() ? "" : ": " + why));
}

namespace {

bool onOff(const std::string& v, bool& out) {
    if (v == "on") out = true;
    else if (v == "off") out = false;
    else return false;
    return true;
}

Entity findEntity(const Editor& ed, const std::string& name) { return findByName(ed.doc.scene.registry, name); }

Result<void> parseStepCount(ScriptCommand& c) {
    double k = 1;
    if (c.args.size() == 1 && (!parseScriptNumber(c.args[0], k) || k < 1 || k > 100000))
        return Error{"N must be 1..100000"};
    c.count = int(k);
    return {};
}

Result<void> parseTimeScale(ScriptCommand& c) {
    if (!parseScriptNumber(c.args[0], c.number) || c.number < 0) return Error{"timescale: expected a number >= 0"};
    return {};
}

void play(ScriptActionRun& r) {
    if (r.ed.sim.state() != SimState::Playing) r.ed.togglePlay();
}

void pause(ScriptActionRun& r) {
    if (r.ed.sim.state() == SimState::Playing) r.ed.togglePlay();
}

void step(ScriptActionRun& r) {
    Editor& ed = r.ed;
    const ScriptCommand& c = r.c;
    for (int i = 0; i < c.count && r.ok(); ++i) {
        ed.stepForward();
        // A diverged step, or a level that cannot be simulated.
        if (ed.sim.diverged() || ed.sim.cannotSimulate())
            r.failLine("step " + std::to_string(i + 1) + " of " + std::to_string(c.count) + ": " + ed.sim.message());
    }
}

void stepBack(ScriptActionRun& r) {
    for (int i = 0; i < r.c.count; ++i) r.ed.stepBack();
}

void open(ScriptActionRun& r) {
    if (!r.ed.open(r.c.args[0])) r.failed("open failed");
}

void save(ScriptActionRun& r) {
    if (r.ed.doc.path.empty()) r.failLine("save: the level has no file yet; use saveas PATH");
    else if (!r.ed.save()) r.failed("save failed");
}

void saveAs(ScriptActionRun& r) {
    if (!r.ed.saveAs(r.c.args[0])) r.failed("saveas failed");
}

void saveState(ScriptActionRun& r) {
    if (!r.ed.saveStateAs(r.c.args[0])) r.failed("savestate failed");
}

void tool(ScriptActionRun& r) {
    const std::string& name = r.c.args[0];
    if (const std::optional<Tool> t = toolFromScriptName(name)) r.ed.tool = *t;
    else r.failLine("tool: unknown tool \"" + name + "\" (" + toolScriptNames(", ") + ")");
}

void select(ScriptActionRun& r) {
    Editor& ed = r.ed;
    const std::vector<std::string>& args = r.c.args;
    std::vector<Entity> sel;
    if (args[0] == "all") sel = ed.doc.scene.registry.entities();
    else if (args[0] != "none")
        for (const std::string& n : args) {
            const Entity e = findEntity(ed, n);
            if (e.isNull()) r.failLine("select: no entity named \"" + n + "\"");
            else sel.push_back(e);
        }
    ed.select(sel);
}

void overlay(ScriptActionRun& r) {
    Editor& ed = r.ed;
    const std::vector<std::string>& args = r.c.args;
    bool on = false;
    const auto& names = render::overlayNames();
    const auto it = std::find_if(names.begin(), names.end(), [&](const auto& p) { return p.first == args[0]; });
    if (it == names.end() || !onOff(args[1], on)) r.failLine("overlay: expected a known overlay and on|off");
    else ed.overlays.bits = on ? ed.overlays.bits | std::uint32_t(it->second) : ed.overlays.bits & ~std::uint32_t(it->second);
}

void system(ScriptActionRun& r) {
    Editor& ed = r.ed;
    const std::vector<std::string>& args = r.c.args;
    bool on = false;
    if (!Simulation::canDisable(args[0]))
        r.failLine("system: unknown system \"" + args[0] + "\" (gravity, drag, springs, attractors, boids, collisions)");
    else if (!onOff(args[1], on)) r.failLine("system: expected on|off");
    else {
        if (on) ed.sim.disabledSystems.erase(args[0]);
        else ed.sim.disabledSystems.insert(args[0]);
        ed.sim.sceneChanged();
    }
}

void snap(ScriptActionRun& r) {
    if (!onOff(r.c.args[0], r.ed.snap)) r.failLine("snap: expected on|off");
}

void timeScale(ScriptActionRun& r) { r.ed.sim.timeScale = r.c.number; }

void breakOnSensor(ScriptActionRun& r) {
    const std::string& arg = r.c.args[0];
    if (arg != "on" && arg != "off") r.failLine("breakonsensor: expected on or off, got \"" + arg + "\"");
    else r.ed.sim.breakOnSensor = arg == "on";
}

void breakOn(ScriptActionRun& r) {
    Editor& ed = r.ed;
    const std::vector<std::string>& args = r.c.args;
    const Entity e = args[0] == "none" ? Entity{} : findEntity(ed, args[0]);
    if (args[0] != "none" && e.isNull()) r.failLine("breakon: no entity named \"" + args[0] + "\"");
    else ed.setBreakOnContact(e);
}

void window(ScriptActionRun& r) {
    bool on = false;
    if (!onOff(r.c.args[1], on) || !r.host.showWindow(r.c.args[0], on))
        r.failLine("window: expected inspector|world|tools|entities|debug|help on|off");
}

void tab(ScriptActionRun& r) {
    if (!r.host.showDebugTab(r.c.args[0])) r.failLine("tab: expected contacts|plots|profile|history");
}

void screenshot(ScriptActionRun& r) {
    r.host.frame();
    if (Result<void> w = r.host.screenshot(r.c.args[0]); !w) r.failLine(w.error());
}

} // namespace

const std::vector<ScriptAction>& scriptActions() {
    static const std::vector<ScriptAction> actions = {
        {"play", 0, 0, "play", nullptr, play},
        {"pause", 0, 0, "pause", nullptr, pause},
        {"step", 0, 1, "step [N]", parseStepCount, step},
        {"stepback", 0, 1, "stepback [N]", parseStepCount, stepBack},
        {"reset", 0, 0, "reset", nullptr, [](ScriptActionRun& r) { r.ed.resetSimulation(); }},
        {"undo", 0, 0, "undo", nullptr, [](ScriptActionRun& r) { r.ed.undo(); }},
        {"redo", 0, 0, "redo", nullptr, [](ScriptActionRun& r) { r.ed.redo(); }},
        {"tool", 1, 1, "tool " + toolScriptNames("|"), nullptr, tool},
        {"select", 1, 1000, "select NAME... | select none | select all", nullptr, select},
        {"overlay", 2, 2, "overlay NAME on|off", nullptr, overlay},
        {"system", 2, 2, "system NAME on|off", nullptr, system},
        {"snap", 1, 1, "snap on|off", nullptr, snap},
        {"timescale", 1, 1, "timescale X", parseTimeScale, timeScale},
        {"breakon", 1, 1, "breakon NAME|none", nullptr, breakOn},
        {"breakonsensor", 1, 1, "breakonsensor on|off", nullptr, breakOnSensor},
        {"fit", 0, 0, "fit", nullptr, [](ScriptActionRun& r) { r.ed.fitView(); }},
        {"new", 0, 0, "new", nullptr, [](ScriptActionRun& r) { r.ed.newDocument(); }},
        {"open", 1, 1, "open PATH", nullptr, open},
        {"save", 0, 0, "save", nullptr, save},
        {"saveas", 1, 1, "saveas PATH", nullptr, saveAs},
        {"savestate", 1, 1, "savestate PATH", nullptr, saveState},
        {"screenshot", 1, 1, "screenshot PATH", nullptr, screenshot, false},
        {"window", 2, 2, "window NAME on|off", nullptr, window},
        {"tab", 1, 1, "tab contacts|plots|profile|history", nullptr, tab},
    };
    return actions;
}

const ScriptAction* findScriptAction(std::string_view name) {
    for (const ScriptAction& a : scriptActions())
        if (a.name == name) return &a;
    return nullptr;
}

bool runScriptAction(Editor& editor, ScriptHost& host, const ScriptCommand& command, const std::string& scriptName) {
    const ScriptAction* action = findScriptAction(command.text);
    ScriptActionRun run(editor, host, command, scriptName);
    if (!action) {
        run.failLine("unknown action \"" + command.text + "\"");
        return false;
    }
    action->run(run);
    if (!action->settles) return run.ok();
    // Any other action that opened an error dialog (play on a level that
    // cannot be simulated, a step that diverged) failed too.
    if (run.ok() && editor.errorModal != run.modalBefore() && !editor.errorModal.empty()) run.failed(action->name.c_str());
    if (run.ok()) host.frame();
    return run.ok();
}

} // namespace stepwise::editor
