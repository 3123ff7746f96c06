#include "ui/session.hpp"

#include "ui/imgui_gl.hpp"

#include <imgui.h>
#include <imgui_internal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

namespace stepwise::ui {

using editor::InputEvent;
using editor::Key;

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

/// Exponential moving average: recent steps weigh most, noise is damped.
void average(double& into, double sample) { into = into == 0.0 ? sample : 0.9 * into + 0.1 * sample; }

const char* kFontPaths[] = {"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
                            "/usr/share/fonts/TTF/DejaVuSans.ttf"};

} // namespace

Session::DialogState Session::dialogState() const {
    DialogState d;
    ImGuiContext* previous = ImGui::GetCurrentContext();
    ImGui::SetCurrentContext(imgui_);
    if (const ImGuiWindow* modal = ImGui::GetTopMostPopupModal()) {
        d.modal = modal->Name;
        d.modal = d.modal.substr(0, d.modal.find("##"));
    }
    ImGui::SetCurrentContext(previous);
    d.status = editor_.status;
    d.openFolder = editor::dialogFolder(editor_.doc.path, ui_.levelsDir).string();
    d.openFiles = editor::levelFiles(d.openFolder).size();
    std::error_code cwd;
    d.saveAsSuggestion = editor::saveAsSuggestion(editor_.doc.path, ui_.levelsDir, std::filesystem::current_path(cwd)).string();
    return d;
}

Result<std::unique_ptr<Session>> Session::create(render::GetProcAddress getProc, const SessionOptions& options) {
    std::unique_ptr<Session> s(new Session());
    s->options_ = options;
    editor::Editor& ed = s->editor_;
    if (!options.configDir.empty()) ed.configDir = options.configDir;
    if (options.persist) s->settings_ = editor::Settings::load(ed.configDir);
    s->ui_.deterministic = options.deterministic;
    std::error_code cwdError;
    s->ui_.levelsDir = !options.levelsDir.empty()
                           ? options.levelsDir
                           : editor::findLevelsDirectory(editor::executableDirectory(), std::filesystem::current_path(cwdError))
                                 .string();
    s->ui_.recentFiles = &s->settings_.recentFiles;
    s->ui_.fontSizeSetting = &s->settings_.fontSize;
    for (const auto& [name, r] : s->settings_.panels) s->ui_.panelFractions[name] = ImVec4(r[0], r[1], r[2], r[3]);

    IMGUI_CHECKVERSION();
    s->imgui_ = ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    if (options.persist) {
        std::error_code ec;
        std::filesystem::create_directories(ed.configDir, ec);
        s->iniPath_ = (ed.configDir / "imgui.ini").string();
        io.IniFilename = s->iniPath_.c_str();
    } else {
        io.IniFilename = nullptr;  // scripted runs: the same layout every time
    }
    if (options.deterministic) io.ConfigInputTextCursorBlink = false;
    io.ConfigWindowsMoveFromTitleBarOnly = true;  // dragging inside a panel is for its widgets
    // One rule for every number field (inspector, World panel, colour
    // channels, snap spacing): a click released without a drag opens the
    // field for typing, so the typed digits never reach the tool keys.
    io.ConfigDragClickToInputText = true;
    // Our Key enum values index KeysDown directly.
    io.KeyMap[ImGuiKey_Tab] = int(Key::Tab);
    io.KeyMap[ImGuiKey_LeftArrow] = int(Key::Left);
    io.KeyMap[ImGuiKey_RightArrow] = int(Key::Right);
    io.KeyMap[ImGuiKey_UpArrow] = int(Key::Up);
    io.KeyMap[ImGuiKey_DownArrow] = int(Key::Down);
    io.KeyMap[ImGuiKey_PageUp] = int(Key::PageUp);
    io.KeyMap[ImGuiKey_PageDown] = int(Key::PageDown);
    io.KeyMap[ImGuiKey_Home] = int(Key::Home);
    io.KeyMap[ImGuiKey_End] = int(Key::End);
    io.KeyMap[ImGuiKey_Delete] = int(Key::Delete);
    io.KeyMap[ImGuiKey_Backspace] = int(Key::Backspace);
    io.KeyMap[ImGuiKey_Space] = int(Key::Space);
    io.KeyMap[ImGuiKey_Enter] = int(Key::Enter);
    io.KeyMap[ImGuiKey_Escape] = int(Key::Escape);
    io.KeyMap[ImGuiKey_A] = int(Key::A);
    io.KeyMap[ImGuiKey_C] = int(Key::C);
    io.KeyMap[ImGuiKey_V] = int(Key::V);
    io.KeyMap[ImGuiKey_X] = int(Key::X);
    io.KeyMap[ImGuiKey_Y] = int(Key::Y);
    io.KeyMap[ImGuiKey_Z] = int(Key::Z);
    s->loadFonts();
    Result<std::unique_ptr<ImGuiGl>> gl = ImGuiGl::create(getProc);
    if (!gl) return Error{gl.error()};
    s->gl_ = std::move(*gl);
    Result<std::unique_ptr<render::Renderer>> r = render::Renderer::create(getProc);
    if (!r) return Error{r.error()};
    s->renderer_ = std::move(*r);
    return s;
}

Session::~Session() {
    gl_.reset();
    renderer_.reset();
    if (imgui_) ImGui::DestroyContext(imgui_);
}

void Session::loadFonts() {
    ImGuiIO& io = ImGui::GetIO();
    io.Fonts->Clear();
    float size = options_.fontSize > 0 ? options_.fontSize
                 : settings_.fontSize > 0 ? settings_.fontSize
                                          : 13.0f * options_.dpiScale;
    size = std::clamp(size, 8.0f, 48.0f);
    ui_.scale = size / 13.0f;
    bool loaded = false;
    // No baked line textures: the atlas is sampled nearest (ui/imgui_gl.cpp).
    io.Fonts->Flags |= ImFontAtlasFlags_NoBakedLines;
    if (!options_.builtinFont) {
        // Glyphs rasterised at their drawn size and placed on whole pixels,
        // so the atlas maps 1:1 to the screen and needs no filtering.
        ImFontConfig config;
        config.OversampleH = 1;
        config.OversampleV = 1;
        config.PixelSnapH = true;
        std::error_code ec;
        // Latin-1 and General Punctuation: the loader's messages quote
        // typographic quotes (“ ” ‘ ’) pasted into a level, and dashes.
        static const ImWchar kRanges[] = {0x0020, 0x00FF, 0x2010, 0x205E, 0};
        for (const char* path : kFontPaths)
            if (std::filesystem::exists(path, ec) &&
                io.Fonts->AddFontFromFileTTF(path, std::round(size * 1.1f), &config, kRanges)) {
                loaded = true;
                break;
            }
    }
    if (!loaded) {
        ImFontConfig config;
        config.SizePixels = std::round(size);
        io.Fonts->AddFontDefault(&config);
    }
    applyTheme(ui_.scale);
}

bool Session::openAtStart(const std::filesystem::path& level) {
    if (!editor_.open(level)) return false;
    settings_.addRecent(level.string());
    lastRecentPath_ = level.string();
    if (options_.persist)
        if (auto recovery = editor_.recoveryAvailable()) ui_.recoveryOffer = recovery->string();
    return true;
}

void Session::saveSettings() {
    if (!options_.persist) return;
    for (const auto& [name, f] : ui_.panelFractions) settings_.panels[name] = {f.x, f.y, f.z, f.w};
    (void)settings_.save(editor_.configDir);
    // imgui.ini holds the panels' pixel rectangles; written only from a
    // window large enough to lay out (a 40x30 window's pile is never saved).
    const ImVec2 display = ImGui::GetIO().DisplaySize;
    if (!iniPath_.empty() && display.x >= kMinLayoutWidth && display.y >= kMinLayoutHeight)
        ImGui::SaveIniSettingsToDisk(iniPath_.c_str());
}

void Session::feedImGui(const std::vector<InputEvent>& events, int width, int height, double frameSeconds) {
    ImGuiIO& io = ImGui::GetIO();
    io.DisplaySize = ImVec2(float(width), float(height));
    // ImGui saves imgui.ini by itself every few seconds: not while the
    // window is too small to hold the layout (see saveSettings).
    if (!iniPath_.empty())
        io.IniFilename = width >= kMinLayoutWidth && height >= kMinLayoutHeight ? iniPath_.c_str() : nullptr;
    io.DeltaTime = float(std::max(frameSeconds, 1e-4));
    io.MouseWheel = 0.0f;
    for (const InputEvent& e : events) {
        switch (e.type) {
        case InputEvent::Type::MouseMove: io.MousePos = ImVec2(float(e.x), float(e.y)); break;
        case InputEvent::Type::MouseDown:
        case InputEvent::Type::MouseUp:
            io.MousePos = ImVec2(float(e.x), float(e.y));
            io.MouseDown[int(e.button)] = e.type == InputEvent::Type::MouseDown;
            break;
        case InputEvent::Type::Wheel: io.MouseWheel += float(e.wheel); break;
        case InputEvent::Type::KeyDown:
        case InputEvent::Type::KeyUp:
            if (e.key != Key::None) io.KeysDown[int(e.key)] = e.type == InputEvent::Type::KeyDown;
            mods_ = e.mods;
            break;
        case InputEvent::Type::Text:
            noteRefusedTyping(e.text);
            io.AddInputCharactersUTF8(e.text.c_str());
            break;
        }
        if (e.type == InputEvent::Type::KeyDown || e.type == InputEvent::Type::KeyUp) {
            io.KeyCtrl = (e.mods & editor::kModCtrl) != 0;
            io.KeyShift = (e.mods & editor::kModShift) != 0;
            io.KeyAlt = (e.mods & editor::kModAlt) != 0;
        }
    }
}

void Session::noteRefusedTyping(const std::string& text) {
    // A number field being typed into (ImGui's text field over a drag
    // widget) drops every character that cannot be part of a number, so
    // "nan" or "inf" would vanish without a word: the dropped characters
    // are kept for the field's panel to report (ui_.refusedTyping). ImGui
    // types into a number only through its "temporary input" over a drag or
    // slider widget, with the filter of ImGuiInputTextFlags_CharsScientific
    // (integers drop 'e' as well; ImGui 1.86 does not record which filter).
    const ImGuiContext& g = *ImGui::GetCurrentContext();
    if (g.ActiveId == 0 || g.TempInputId != g.ActiveId || !ImGui::GetInputTextState(g.ActiveId)) return;
    if (ui_.refusedTypingFor != g.ActiveId) ui_.refusedTyping.clear();
    for (const char c : text) {
        const bool kept = (c >= '0' && c <= '9') || c == '.' || c == '+' || c == '-' || c == '*' || c == '/' ||
                          c == 'e' || c == 'E';
        if (!kept) ui_.refusedTyping += c;
    }
    if (!ui_.refusedTyping.empty()) ui_.refusedTypingFor = g.ActiveId;
}

void Session::route(const std::vector<InputEvent>& events) {
    const ImGuiIO& io = ImGui::GetIO();
    // Keys belong to a text field while one has the keyboard: one that
    // was active last frame (WantTextInput) or that became active in this
    // very frame (a number field just clicked opens its text field as the
    // mouse is released).
    const ImGuiID active = ImGui::GetActiveID();
    const bool typing = io.WantTextInput || (active != 0 && GImGui->TempInputId == active);
    const ImVec2 o = ui_.viewportPos;
    // Any open popup (modal, menu, combo) owns the input until it closes.
    const bool modal = ImGui::IsPopupOpen("", ImGuiPopupFlags_AnyPopupId);
    for (const InputEvent& e : events) {
        switch (e.type) {
        case InputEvent::Type::KeyDown:
            // Keys belong to a text field while one is active, and to a
            // modal while one is open.
            if (!typing && !modal) editor_.handleShortcut(e.key, e.mods);
            break;
        case InputEvent::Type::MouseDown:
        case InputEvent::Type::MouseUp:
        case InputEvent::Type::MouseMove:
        case InputEvent::Type::Wheel: {
            const bool inside = e.x >= o.x && e.y >= o.y && e.x < o.x + ui_.viewportSize.x && e.y < o.y + ui_.viewportSize.y;
            const bool ours = viewportCapture_ || (ui_.viewportHovered && inside && !modal);
            if (e.type == InputEvent::Type::MouseDown && ours) viewportCapture_ = true;
            if (!ours) break;
            InputEvent local = e;
            local.x = e.x - o.x;
            local.y = e.y - o.y;
            if (e.type == InputEvent::Type::MouseDown || e.type == InputEvent::Type::MouseUp) local.mods = mods_;
            editor_.handleViewportEvent(local);
            if (e.type == InputEvent::Type::MouseUp) viewportCapture_ = false;
            break;
        }
        default: break;
        }
    }
}

void Session::frame(int width, int height, double frameSeconds, const std::function<void()>& presentPrevious) {
    const auto t0 = Clock::now();
    // This frame's events: stop before a second mouse-button change.
    std::vector<InputEvent> batch;
    int buttonChanges = 0;
    while (!events_.empty()) {
        const InputEvent& e = events_.front();
        const bool button = e.type == InputEvent::Type::MouseDown || e.type == InputEvent::Type::MouseUp;
        const bool key = e.type == InputEvent::Type::KeyDown || e.type == InputEvent::Type::KeyUp;
        if ((button || key) && buttonChanges == 1) break;
        if (button || key) ++buttonChanges;
        batch.push_back(e);
        events_.pop_front();
    }
    for (const InputEvent& e : batch)
        if (e.type == InputEvent::Type::KeyDown || e.type == InputEvent::Type::KeyUp) mods_ = e.mods;

    feedImGui(batch, width, height, frameSeconds);
    ImGui::NewFrame();
    drawEditorUi(ui_, editor_);
    // Route after the panels so we know whether the viewport is under the
    // mouse (this frame's layout) and whether a text field has the keys.
    route(batch);
    if (ui_.fontChanged) ui_.fontChanged = false;  // applied below, outside the frame
    ImGui::Render();
    const double uiMs = msSince(t0);

    const auto t1 = Clock::now();
    const std::uint64_t stepsBefore = editor_.sim.steps();
    editor_.update(frameSeconds);
    ui_.lastFrame.steps = editor_.sim.steps() >= stepsBefore ? int(editor_.sim.steps() - stepsBefore) : 0;
    ui_.lastFrame.stepMs = msSince(t1);
    if (editor_.sim.state() == editor::SimState::Playing) average(ui_.stepMs, editor_.sim.lastFrameStepMs());
    if (const World* w = editor_.sim.world(); w && editor_.sim.state() == editor::SimState::Playing) {
        for (const StageTime& s : w->lastStats().stages) average(ui_.stageAverage["stage:" + std::string(s.name)], s.milliseconds);
        for (const StageTime& s : w->lastStats().systems) average(ui_.stageAverage["system:" + std::string(s.name)], s.milliseconds);
    }

    // Viewport: the shared renderer, straight into the window.
    const auto t2 = Clock::now();
    const int vw = std::max(16, int(ui_.viewportSize.x)), vh = std::max(16, int(ui_.viewportSize.y));
    editor_.setViewportSize(vw, vh);
    if (editor_.sim.running()) editor_.sim.ensureWorld(editor_.doc.scene);
    render::FrameInput input = editor_.frameInput();
    if (!input.world && (editor_.overlays.has(render::Overlay::ForceField) || editor_.overlays.has(render::Overlay::Force))) {
        // Editing: the preview World gives the force overlays.
        input.world = panelWorld(ui_, editor_);
        if (input.world) {
            if (editor_.overlays.has(render::Overlay::ForceField)) input.overlays.add(render::Overlay::ForceField);
            if (editor_.overlays.has(render::Overlay::Force)) input.overlays.add(render::Overlay::Force);
        }
    }
    input.caption.clear();
    // The viewport's line about edits while running (viewport_panel.cpp)
    // sits at the top of the scene: the legend stays below it.
    if (!editor_.runningEditsNote().empty()) input.reservedTopPx = ImGui::GetFontSize() + 10 * ui_.scale;
    const render::DrawData drawn = render::buildDrawData(input, vw, vh);
    const double buildMs = msSince(t2);

    // The previous frame leaves the back buffer only now: all of the above
    // ran while llvmpipe's threads were still drawing it.
    const auto tPresent = Clock::now();
    if (presentPrevious) presentPrevious();
    const double presentMs = msSince(tPresent);

    // Straight into the window at the viewport panel's place (GL counts
    // rows from the bottom), under the panels ImGui draws next.
    const auto tDraw = Clock::now();
    gl_->clear(width, height, kPanelBackground);
    renderer_->draw(drawn, int(ui_.viewportPos.x), height - int(ui_.viewportPos.y) - vh);
    ui_.lastFrame.instances = drawn.instanceCount();
    ui_.lastFrame.drawCalls = renderer_->lastDrawCalls();
    ui_.lastFrame.legendBox = drawn.legendBox;
    ui_.lastFrame.legendRows = drawn.legend.size();
    const double sceneMs = buildMs + msSince(tDraw);
    const auto t3 = Clock::now();
    renderer_->flush();  // llvmpipe starts on the viewport while ImGui's lists are submitted
    gl_->render(ImGui::GetDrawData(), width, height);
    renderer_->flush();
    ui_.lastFrame.uiMs = uiMs;
    ui_.lastFrame.sceneMs = sceneMs;
    ui_.lastFrame.drawUiMs = msSince(t3);
    ui_.lastFrame.presentMs = presentMs;
    average(ui_.uiMs, uiMs);
    average(ui_.sceneMs, sceneMs);
    average(ui_.frameMs, msSince(t0));

    // Recent files follow what is open.
    if (!editor_.doc.path.empty() && editor_.doc.path.string() != lastRecentPath_) {
        lastRecentPath_ = editor_.doc.path.string();
        settings_.addRecent(lastRecentPath_);
        // A level opened from the menu gets the same recovery offer as one
        // opened at start (after a Save As there is none: it was removed).
        if (options_.persist)
            if (auto recovery = editor_.recoveryAvailable()) ui_.recoveryOffer = recovery->string();
        if (options_.persist) (void)settings_.save(editor_.configDir);
    }
    if (settings_.fontSize > 0 && std::abs(settings_.fontSize / 13.0f - ui_.scale) > 1e-3f && !ImGui::IsAnyItemActive()) {
        options_.fontSize = settings_.fontSize;
        loadFonts();
        gl_->rebuildFonts();
        if (options_.persist) (void)settings_.save(editor_.configDir);
    }
}

render::Image Session::capture(int width, int height) {
    return renderer_->readPixels(width, height);
}

} // namespace stepwise::ui
