#pragma once
/// \file editor_ui.hpp
/// The Dear ImGui panels of the editor: menu bar, tools, entity list,
/// viewport, inspector, world panel (settings, integrator + stiffness hint,
/// system switches with their cost per step), contacts table, plots, help
/// and the file dialogs. Panels only read the Editor and call its
/// functions; every change to the level goes through Editor::applyEdit.

#include "app/editor.hpp"

#include <imgui.h>

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace stepwise::ui {

/// Default positions of the panels for a window of w x h at UI scale s
/// (pixels). Panels start there (ImGuiCond_FirstUseEver); imgui.ini then
/// remembers where the user put them.
struct PanelRects {
    ImVec2 toolsPos, toolsSize, entitiesPos, entitiesSize, viewportPos, viewportSize, inspectorPos, inspectorSize,
        worldPos, worldSize, debugPos, debugSize;
};
PanelRects defaultLayout(float width, float height, float scale);

/// Below this window size no layout is recorded or saved (ImGui piles the
/// panels at the top left); the last good one comes back when it grows.
constexpr float kMinLayoutWidth = 320.0f, kMinLayoutHeight = 240.0f;

struct UiState {
    float scale = 1.0f;                 ///< UI scale (DPI or font size / 13)
    bool deterministic = false;         ///< scripted mode: hide wall-clock numbers
    /// Folder of the level files (absolute, found by editor::findLevelsDirectory).
    std::string levelsDir = "levels";
    std::vector<std::string>* recentFiles = nullptr;  ///< owned by the session's Settings
    float* fontSizeSetting = nullptr;
    bool fontChanged = false;

    // Layout: each panel's rectangle as fractions (x, y, w, h) of the window,
    // from the last frame whose window was large enough; saved in the
    // settings and scaled to the window at start and on every resize, so a
    // layout from 1600x900 opens on-screen at 1280x720.
    std::map<std::string, ImVec4, std::less<>> panelFractions;
    ImVec2 layoutDisplay{0, 0};          ///< window size the fractions were recorded at
    bool layoutInterrupted = false;      ///< the window was too small since the last recording
    bool resetLayoutRequested = false;   ///< View > Reset layout
    enum class ApplyLayout : std::uint8_t { None, Fractions, Default };
    ApplyLayout applyLayout = ApplyLayout::None;  ///< this frame's placement (beginLayout)

    // Windows
    bool showTools = true, showEntities = true, showInspector = true, showWorld = true, showDebug = true;
    bool showHelp = false;
    int debugTab = 0;                   ///< 0 contacts, 1 plots, 2 profile, 3 history

    // Viewport, filled by drawEditorUi each frame
    ImVec2 viewportPos{0, 0}, viewportSize{1, 1};
    bool viewportHovered = false;
    /// This frame's inspector fields as window-pixel rectangles (x, y, w, h),
    /// keyed "inspector/<component>" or "inspector/<component>.<field>":
    /// --debug-state reports them, so a test clicks a field wherever the
    /// layout and the window size put it.
    std::map<std::string, ImVec4, std::less<>> widgetRects;
    /// The Error modal's Enter: set once Enter is up while the modal shows.
    bool errorEnterArmed = false;

    // Dialog buffers
    std::string openPath, saveAsPath, entityFilter, contactFilter;
    bool openDialogRequested = false, saveAsDialogRequested = false, saveStateRequested = false;
    std::optional<std::string> recoveryOffer;  ///< path of a recovery file to offer once
    std::optional<std::string> replaceConfirm; ///< Save as onto this existing file: asked first
    bool replaceIsState = false;               ///< ... for "Save simulation state as"

    // Inspector edit coalescing: the widget being dragged and its merge key.
    ImGuiID activeWidget = 0;
    std::uint64_t activeKey = 0;
    /// Characters typed into the number field `refusedTypingFor` that
    /// cannot be part of a number (ImGui drops them): its panel says so.
    std::string refusedTyping;
    ImGuiID refusedTypingFor = 0;
    /// The number field being dragged and its speed per pixel, fixed from
    /// its value when the drag started: drags are linear.
    ImGuiID dragSpeedFor = 0;
    float dragSpeed = 0.0f;

    // Timing (ms), averaged, for the status bar and the profile
    double frameMs = 0.0, uiMs = 0.0, sceneMs = 0.0, stepMs = 0.0;
    /// The last frame's parts, unaveraged (for `edit --bench-frames`): ms,
    /// and the physics steps it took.
    struct FrameParts {
        double uiMs = 0.0, stepMs = 0.0, sceneMs = 0.0, drawUiMs = 0.0;
        double presentMs = 0.0;     ///< the previous frame's swap, run inside this one (Session::frame)
        std::size_t instances = 0;  ///< instances the viewport drew
        int drawCalls = 0;          ///< the viewport's draw calls
        int steps = 0;
        /// The viewport's legend panel, pixels (x, y, width, height; y up
        /// from the viewport's bottom, as render::DrawData::legendBox).
        std::array<double, 4> legendBox{};
        std::size_t legendRows = 0;  ///< its arrow overlays' references (DrawData::legend)
    } lastFrame;
    std::map<std::string, double, std::less<>> stageAverage;  ///< ms per step, moving average

    // A World built from the edited scene while editing (hints, active
    // systems, force field): rebuilt when the scene's revision changes.
    std::string previewError;  ///< why the edited scene cannot be simulated
    /// Entities past which the edit-mode World is not recompiled every edit (cost).
    std::size_t previewLimit = 20000;
};

/// The panels' background colour, which is also what ImGuiGl::clear() fills
/// the window with: a panel that overlaps nothing can leave its background
/// out (see beginPanel()).
inline const ImVec4 kPanelBackground{0.075f, 0.082f, 0.102f, 1.0f};

/// Applies the theme (dark, matching the renderer's background) at `scale`.
void applyTheme(float scale);

/// ImGui::Begin for a panel, leaving its background out when, as of the
/// last frame, no other window overlaps it and none is being moved or
/// resized: the window was cleared to the same colour, and blending the
/// panels' ~600,000 background pixels costs llvmpipe about 2 ms a frame. A
/// panel dragged onto another has its background again from that frame.
bool beginPanel(const char* name, bool* open, ImGuiWindowFlags flags = 0);

/// SetNextWindowPos/Size for panel `name` by this frame's layout decision.
void placePanel(const UiState& ui, const char* name, ImVec2 defaultPos, ImVec2 defaultSize);

/// Builds every panel for this frame. Call between ImGui::NewFrame and
/// ImGui::Render.
void drawEditorUi(UiState& ui, editor::Editor& ed);

/// The inspector panel (inspector.cpp): driven by the component table.
void drawInspector(UiState& ui, editor::Editor& ed);
/// The World panel's widget for world setting `key` (inspector.cpp), driven
/// by the world-settings table: range, unit and description from the table,
/// the edit checked as the loader checks it (editor::setWorldField).
bool worldFieldWidget(UiState& ui, editor::Editor& ed, std::string_view key);

/// While the number field just drawn is typed into, ImGui drops the
/// characters that cannot be part of a number; this puts them in the status
/// line, naming the field (`who` "world." or "\"bob\" ", `field` "dt").
void reportRefusedTyping(UiState& ui, editor::Editor& ed, const std::string& who, std::string_view field);

/// Records the last item's rectangle in `ui.widgetRects` under `key`.
void recordWidgetRect(UiState& ui, const std::string& key);

/// `text` with the typographic quotes and dashes the current font has no
/// glyph for replaced by ASCII (else ImGui draws '?').
std::string displayableText(const std::string& text);

/// The World the panels read: the running one, else the edit-mode preview.
const World* panelWorld(UiState& ui, editor::Editor& ed);

} // namespace stepwise::ui
