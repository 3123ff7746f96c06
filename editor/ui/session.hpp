#pragma once
/// \file session.hpp
/// One editor session on a GL context: the Editor model, the ImGui context
/// and panels, the scene renderer and the ImGui GL backend. The SDL window
/// and the headless scripted mode both call queue() with InputEvents and
/// frame() once per displayed frame; nothing else differs between them, so
/// a script replays exactly what a person's input does.

#include "app/editor.hpp"
#include "image.hpp"
#include "renderer.hpp"
#include "ui/editor_ui.hpp"

#include <deque>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

struct ImGuiContext;

namespace stepwise::ui {

class ImGuiGl;

struct SessionOptions {
    float fontSize = 0.0f;        ///< pixels; 0: 13 px times the DPI scale (or the saved setting)
    float dpiScale = 1.0f;        ///< display DPI / 96
    bool builtinFont = false;     ///< ImGui's embedded font (deterministic screenshots everywhere)
    bool persist = true;          ///< imgui.ini and settings in the config folder
    bool deterministic = false;   ///< hide wall-clock numbers (scripted screenshots)
    /// Folder of level files for the Open list and Save as; "" finds it
    /// from the executable's place (editor::findLevelsDirectory).
    std::string levelsDir;
    std::filesystem::path configDir;  ///< empty: editor::configDirectory()
};

class Session {
public:
    static Result<std::unique_ptr<Session>> create(render::GetProcAddress getProc, const SessionOptions& options);
    ~Session();

    editor::Editor& editor() { return editor_; }
    UiState& ui() { return ui_; }

    /// Input for the coming frames. A frame takes events up to the second
    /// mouse-button change (ImGui 1.86 sees one button state per frame, so a
    /// click is spread over two frames instead of being lost).
    void queue(const editor::InputEvent& e) { events_.push_back(e); }
    bool hasQueuedEvents() const { return !events_.empty(); }

    /// Runs one frame of width x height window pixels: input, panels,
    /// simulation (frameSeconds of time), viewport and UI drawing into the
    /// default framebuffer, then a flush so rasterising starts at once.
    /// `presentPrevious` (the window's buffer swap of the last frame) runs
    /// just before the first GL call: everything up to there (input,
    /// panels, physics, building the viewport's shapes) is CPU work that
    /// overlaps llvmpipe's threads finishing the previous frame.
    void frame(int width, int height, double frameSeconds, const std::function<void()>& presentPrevious = {});

    /// Reads the default framebuffer (after frame()).
    render::Image capture(int width, int height);

    /// Viewport image rectangle in window pixels (from the last frame).
    ImVec2 viewportPos() const { return ui_.viewportPos; }
    ImVec2 viewportSize() const { return ui_.viewportSize; }

    /// What the dialogs show, for --debug-state (the end-to-end test drives
    /// the real window by it): the open modal's title ("" for none), the
    /// status line, the Open dialog's folder and its number of level files,
    /// and the path Save as proposes.
    struct DialogState {
        std::string modal, status, openFolder, saveAsSuggestion;
        std::size_t openFiles = 0;
    };
    DialogState dialogState() const;

    /// Saves settings (recent files, font size) and imgui.ini when persisting.
    void saveSettings();
    bool wantsQuit() const { return editor_.quitRequested(); }
    /// Opens a level at start (adds it to the recent files, offers recovery).
    bool openAtStart(const std::filesystem::path& level);

private:
    Session() = default;
    void loadFonts();
    void feedImGui(const std::vector<editor::InputEvent>& events, int width, int height, double frameSeconds);
    void route(const std::vector<editor::InputEvent>& events);
    void noteRefusedTyping(const std::string& text);

    editor::Editor editor_;
    UiState ui_;
    SessionOptions options_;
    editor::Settings settings_;
    std::string iniPath_;
    ImGuiContext* imgui_ = nullptr;
    std::unique_ptr<ImGuiGl> gl_;
    std::unique_ptr<render::Renderer> renderer_;
    std::deque<editor::InputEvent> events_;
    bool viewportCapture_ = false;     // a drag that started in the viewport owns the mouse
    std::uint8_t mods_ = 0;
    bool mouseDown_[3] = {false, false, false};
    std::string lastRecentPath_;
};

} // namespace stepwise::ui
