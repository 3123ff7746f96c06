#include "ui/editor_ui.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"
#include "stepwise/integrators.hpp"
#include "stepwise/scene_io.hpp"

#include <imgui_internal.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace stepwise::ui {

using editor::Editor;
using editor::Key;
using editor::SimState;
using editor::Tool;

namespace {

const ImVec4 kAccent{0.35f, 0.62f, 0.95f, 1.0f};
const ImVec4 kGold{1.0f, 0.82f, 0.40f, 1.0f};
const ImVec4 kRed{0.95f, 0.42f, 0.38f, 1.0f};
const ImVec4 kGreen{0.45f, 0.85f, 0.55f, 1.0f};
const ImVec4 kDim{0.60f, 0.63f, 0.68f, 1.0f};

void helpMarker(const char* text) {
    ImGui::SameLine();
    ImGui::TextDisabled("(?)");
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", text);
}

/// Every shortcut, once, for the help window (the menus show their own
/// shortcut hints; keep both in step).
struct Shortcut {
    const char* keys;
    const char* what;
};
const Shortcut kShortcuts[] = {
    {"Space", "Play / pause"},
    {"Right", "Step one dt (pauses)"},
    {"Left", "Step back through the history"},
    {"R", "Reset to the edited level"},
    {"Ctrl+Z", "Undo"},
    {"Ctrl+Shift+Z, Ctrl+Y", "Redo"},
    {"Delete, Backspace", "Delete the selection (and springs attached to it)"},
    {"Ctrl+D", "Duplicate the selection"},
    {"Ctrl+C / Ctrl+V", "Copy / paste"},
    {"Ctrl+A", "Select all"},
    {"Esc", "Clear the selection, cancel a spring or a polygon"},
    {"Enter", "Polygon tool: make the clicked outline (or right click)"},
    {"Ctrl+S / Ctrl+Shift+S", "Save / save as"},
    {"Ctrl+O / Ctrl+N", "Open / new level"},
    {"Ctrl+Q", "Quit (asks about unsaved changes)"},
    {"1 .. 9, 0", "Tools: select, rotate, circle, box, wall, spring, attractor, boid brush, joint, polygon"},
    {"G", "Snap to grid on / off"},
    {"F", "Frame the whole level"},
    {"F1", "This help"},
    {"Left drag", "Select tool: move the selection, or box-select on empty space"},
    {"Shift/Ctrl+click", "Add to / remove from the selection"},
    {"Middle or right drag", "Pan"},
    {"Wheel", "Zoom about the cursor"},
    {"Left drag while playing", "Pull a body with a mouse spring"},
};

std::string levelLabel(const Editor& ed) { return ed.doc.title() + (ed.dirty() ? " *" : ""); }

} // namespace

PanelRects defaultLayout(float width, float height, float scale) {
    PanelRects r;
    const float menu = 13.0f * scale + 8.0f;    // menu bar: font height + frame padding
    const float status = 13.0f * scale + 10.0f;  // status bar
    float left = std::round(230.0f * scale), right = std::round(330.0f * scale);
    // A narrow window: the side panels give way so the viewport keeps 40%
    // of the width (at 320 px wide it was pushed off the right edge).
    if (width - left - right < 0.4f * width) {
        const float shrink = 0.6f * width / (left + right);
        left = std::floor(left * shrink);
        right = std::floor(right * shrink);
    }
    const float bottom = std::round(std::min(230.0f * scale, 0.3f * height));
    const float top = menu, usable = height - menu - status;
    const float centerW = width - left - right;
    const float toolsH = std::round(std::min(300.0f * scale, usable * 0.45f));
    r.toolsPos = {0, top};
    r.toolsSize = {left, toolsH};
    r.entitiesPos = {0, top + toolsH};
    r.entitiesSize = {left, usable - toolsH};
    r.viewportPos = {left, top};
    r.viewportSize = {centerW, usable - bottom};
    r.debugPos = {left, top + usable - bottom};
    r.debugSize = {centerW, bottom};
    const float inspectorH = std::round(usable * 0.52f);
    r.inspectorPos = {left + centerW, top};
    r.inspectorSize = {right, inspectorH};
    r.worldPos = {left + centerW, top + inspectorH};
    r.worldSize = {right, usable - inspectorH};
    return r;
}

void placePanel(const UiState& ui, const char* name, ImVec2 defaultPos, ImVec2 defaultSize) {
    const ImVec2 display = ImGui::GetIO().DisplaySize;
    if (ui.applyLayout == UiState::ApplyLayout::Default) {
        ImGui::SetNextWindowPos(defaultPos, ImGuiCond_Always);
        ImGui::SetNextWindowSize(defaultSize, ImGuiCond_Always);
        return;
    }
    if (ui.applyLayout == UiState::ApplyLayout::Fractions) {
        if (const auto it = ui.panelFractions.find(name); it != ui.panelFractions.end()) {
            const ImVec4 f = it->second;
            // Scaled to the window, then kept inside it.
            ImVec2 size(std::min(f.z * display.x, display.x), std::min(f.w * display.y, display.y));
            ImVec2 pos(std::clamp(f.x * display.x, 0.0f, display.x - size.x),
                       std::clamp(f.y * display.y, 0.0f, display.y - size.y));
            ImGui::SetNextWindowPos(ImVec2(std::round(pos.x), std::round(pos.y)), ImGuiCond_Always);
            ImGui::SetNextWindowSize(ImVec2(std::round(size.x), std::round(size.y)), ImGuiCond_Always);
            return;
        }
    }
    ImGui::SetNextWindowPos(defaultPos, ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(defaultSize, ImGuiCond_FirstUseEver);
}

bool beginPanel(const char* name, bool* open, ImGuiWindowFlags flags) {
    const ImGuiContext& g = *GImGui;
    const ImGuiWindow* self = ImGui::FindWindowByName(name);
    // A drag that moves or resizes a window can make an overlap this frame.
    const bool arranging = g.MovingWindow != nullptr ||
                           (g.ActiveId != 0 && g.ActiveIdWindow != nullptr && g.ActiveIdWindow == g.ActiveIdWindow->RootWindow &&
                            ImGui::IsMouseDragging(ImGuiMouseButton_Left) && g.ActiveIdWindow->Name != std::string_view("Viewport"));
    bool alone = self != nullptr && !arranging;
    if (alone) {
        const ImRect rect = self->Rect();
        for (const ImGuiWindow* w : g.Windows) {
            if (w == self || !w->WasActive || w->Hidden) continue;
            if ((w->Flags & (ImGuiWindowFlags_ChildWindow | ImGuiWindowFlags_Popup | ImGuiWindowFlags_Tooltip)) != 0)
                continue;  // inside a window, or drawn over it with its own background
            if (w->Rect().Overlaps(rect)) {
                alone = false;
                break;
            }
        }
    }
    if (alone) ImGui::SetNextWindowBgAlpha(0.0f);
    return ImGui::Begin(name, open, flags);
}

void applyTheme(float scale) {
    ImGuiStyle& style = ImGui::GetStyle();
    style = ImGuiStyle();
    ImGui::StyleColorsDark(&style);
    style.AntiAliasedLinesUseTex = false;  // the font atlas is sampled nearest (ui/imgui_gl.cpp)
    style.WindowRounding = 0.0f;
    style.FrameRounding = 3.0f;
    style.GrabRounding = 3.0f;
    style.TabRounding = 3.0f;
    style.WindowBorderSize = 1.0f;
    style.FrameBorderSize = 0.0f;
    style.WindowPadding = {8, 6};
    style.ItemSpacing = {6, 4};
    style.ScrollbarSize = 12;
    ImVec4* c = style.Colors;
    // Panels a shade lighter than the viewport's #0f1218 so it reads as a canvas.
    c[ImGuiCol_WindowBg] = kPanelBackground;
    // Children (scrolling tables, lists) show their panel's background, or
    // the cleared window of the same colour: drawing their own is overdraw.
    c[ImGuiCol_ChildBg] = {kPanelBackground.x, kPanelBackground.y, kPanelBackground.z, 0.0f};
    c[ImGuiCol_PopupBg] = {0.10f, 0.11f, 0.135f, 0.98f};
    c[ImGuiCol_MenuBarBg] = {0.10f, 0.11f, 0.135f, 1.0f};
    c[ImGuiCol_TitleBg] = {0.10f, 0.11f, 0.135f, 1.0f};
    c[ImGuiCol_TitleBgActive] = {0.13f, 0.15f, 0.19f, 1.0f};
    c[ImGuiCol_Border] = {0.18f, 0.20f, 0.24f, 1.0f};
    c[ImGuiCol_FrameBg] = {0.13f, 0.145f, 0.175f, 1.0f};
    c[ImGuiCol_FrameBgHovered] = {0.18f, 0.20f, 0.25f, 1.0f};
    c[ImGuiCol_FrameBgActive] = {0.22f, 0.25f, 0.31f, 1.0f};
    c[ImGuiCol_Header] = {0.17f, 0.24f, 0.34f, 1.0f};
    c[ImGuiCol_HeaderHovered] = {0.22f, 0.32f, 0.46f, 1.0f};
    c[ImGuiCol_HeaderActive] = {0.26f, 0.40f, 0.58f, 1.0f};
    c[ImGuiCol_Button] = {0.16f, 0.19f, 0.24f, 1.0f};
    c[ImGuiCol_ButtonHovered] = {0.22f, 0.32f, 0.46f, 1.0f};
    c[ImGuiCol_ButtonActive] = {0.26f, 0.40f, 0.58f, 1.0f};
    c[ImGuiCol_Tab] = {0.12f, 0.14f, 0.18f, 1.0f};
    c[ImGuiCol_TabActive] = {0.20f, 0.28f, 0.40f, 1.0f};
    c[ImGuiCol_TabHovered] = {0.24f, 0.34f, 0.48f, 1.0f};
    c[ImGuiCol_CheckMark] = kAccent;
    c[ImGuiCol_SliderGrab] = kAccent;
    c[ImGuiCol_PlotLines] = kAccent;
    c[ImGuiCol_TableHeaderBg] = {0.12f, 0.14f, 0.18f, 1.0f};
    style.ScaleAllSizes(scale);
}

const World* panelWorld(UiState& ui, Editor& ed) {
    if (ed.sim.running()) {
        ed.sim.ensureWorld(ed.doc.scene);
        return ed.sim.world();
    }
    // Editing: the simulation's one World, recompiled in place after edits
    // (no second World of the UI's own).
    if (ed.doc.scene.registry.size() > ui.previewLimit) return nullptr;
    const World* w = ed.sim.editingWorld(ed.doc.scene);
    ui.previewError = ed.sim.editingWorldError();
    return w;
}

namespace {

// ---- menus -----------------------------------------------------------------------

// ---- layout ------------------------------------------------------------------------

const char* const kPanelNames[] = {"Tools", "Entities", "Viewport", "Inspector", "World", "Debug"};

bool usableLayoutSize(ImVec2 display) { return display.x >= kMinLayoutWidth && display.y >= kMinLayoutHeight; }

/// Decides this frame's placement: the default (Reset layout, or nothing
/// known), the remembered fractions scaled to a window whose size changed
/// (or that was too small to lay out meanwhile, when ImGui clamped every
/// panel towards the top left), or wherever the panels are (ImGui's own).
void beginLayout(UiState& ui, ImVec2 display) {
    ui.applyLayout = UiState::ApplyLayout::None;
    if (!usableLayoutSize(display)) {
        ui.layoutInterrupted = true;  // nothing is recorded; the panels come back when the window does
        return;
    }
    if (ui.resetLayoutRequested) {
        ui.resetLayoutRequested = false;
        ui.applyLayout = UiState::ApplyLayout::Default;
    } else if (!ui.panelFractions.empty() &&
               (ui.layoutInterrupted || display.x != ui.layoutDisplay.x || display.y != ui.layoutDisplay.y)) {
        ui.applyLayout = UiState::ApplyLayout::Fractions;
    }
    ui.layoutInterrupted = false;
}

/// Records where the panels are, as fractions of the window, when the
/// window is large enough to hold a layout; never while it is not, so a
/// window shrunk to 40x30 neither keeps nor saves the pile it makes.
void endLayout(UiState& ui, ImVec2 display) {
    if (!usableLayoutSize(display)) return;
    for (const char* name : kPanelNames) {
        const ImGuiWindow* w = ImGui::FindWindowByName(name);
        if (!w || !w->WasActive) continue;
        ui.panelFractions[name] = ImVec4(w->Pos.x / display.x, w->Pos.y / display.y, w->Size.x / display.x,
                                         w->Size.y / display.y);
    }
    ui.layoutDisplay = display;
}

void menuBar(UiState& ui, Editor& ed) {
    if (!ImGui::BeginMainMenuBar()) return;
    if (ImGui::BeginMenu("File")) {
        if (ImGui::MenuItem("New", "Ctrl+N")) ed.request(editor::PendingAction::New);
        if (ImGui::MenuItem("Open...", "Ctrl+O")) ui.openDialogRequested = true;
        if (ImGui::BeginMenu("Open recent", ui.recentFiles && !ui.recentFiles->empty())) {
            for (const std::string& f : *ui.recentFiles)
                if (ImGui::MenuItem(f.c_str())) ed.request(editor::PendingAction::Open, f);
            ImGui::EndMenu();
        }
        ImGui::Separator();
        if (ImGui::MenuItem("Save", "Ctrl+S")) ed.save();
        if (ImGui::MenuItem("Save as...", "Ctrl+Shift+S")) ui.saveAsDialogRequested = true;
        if (ImGui::MenuItem("Save simulation state as...", nullptr, false, ed.sim.running())) ui.saveStateRequested = true;
        ImGui::Separator();
        if (ImGui::MenuItem("Quit", "Ctrl+Q")) ed.request(editor::PendingAction::Quit);
        ImGui::EndMenu();
    }
    if (ImGui::BeginMenu("Edit")) {
        if (ImGui::MenuItem("Undo", "Ctrl+Z", false, ed.commands.canUndo())) ed.undo();
        if (ImGui::MenuItem("Redo", "Ctrl+Shift+Z", false, ed.commands.canRedo())) ed.redo();
        ImGui::Separator();
        const bool any = !ed.selection.empty();
        if (ImGui::MenuItem("Copy", "Ctrl+C", false, any)) ed.copySelection();
        if (ImGui::MenuItem("Paste", "Ctrl+V", false, ed.hasClipboard())) ed.paste();
        if (ImGui::MenuItem("Duplicate", "Ctrl+D", false, any)) ed.duplicateSelection();
        if (ImGui::MenuItem("Delete", "Delete", false, any)) ed.deleteSelection();
        if (ImGui::MenuItem("Select all", "Ctrl+A")) ed.selectAll();
        ImGui::EndMenu();
    }
    if (ImGui::BeginMenu("Simulation")) {
        if (ImGui::MenuItem(ed.sim.state() == SimState::Playing ? "Pause" : "Play", "Space")) ed.togglePlay();
        if (ImGui::MenuItem("Step", "Right")) ed.stepForward();
        if (ImGui::MenuItem("Step back", "Left", false, ed.sim.historySize() > 0)) ed.stepBack();
        if (ImGui::MenuItem("Reset", "R", false, ed.sim.running())) ed.resetSimulation();
        ImGui::EndMenu();
    }
    if (ImGui::BeginMenu("View")) {
        for (const auto& [name, overlay] : render::overlayNames()) {
            bool on = ed.overlays.has(overlay);
            if (ImGui::MenuItem(std::string(name).c_str(), nullptr, &on))
                ed.overlays.bits = on ? ed.overlays.bits | std::uint32_t(overlay) : ed.overlays.bits & ~std::uint32_t(overlay);
        }
        ImGui::Separator();
        ImGui::MenuItem("Snap to grid", "G", &ed.snap);
        if (ImGui::MenuItem("Frame level", "F")) ed.fitView();
        ImGui::Separator();
        ImGui::MenuItem("Tools", nullptr, &ui.showTools);
        ImGui::MenuItem("Entities", nullptr, &ui.showEntities);
        ImGui::MenuItem("Inspector", nullptr, &ui.showInspector);
        ImGui::MenuItem("World", nullptr, &ui.showWorld);
        ImGui::MenuItem("Debug (contacts, plots, profile)", nullptr, &ui.showDebug);
        if (ImGui::MenuItem("Reset layout")) {
            // Every panel back where a first start puts it, and shown.
            ui.resetLayoutRequested = true;
            ui.showTools = ui.showEntities = ui.showInspector = ui.showWorld = ui.showDebug = true;
        }
        if (ui.fontSizeSetting) {
            ImGui::Separator();
            float size = *ui.fontSizeSetting > 0 ? *ui.fontSizeSetting : 13.0f * ui.scale;
            ImGui::SetNextItemWidth(120 * ui.scale);
            if (ImGui::SliderFloat("Font size", &size, 8.0f, 32.0f, "%.0f px")) {
                *ui.fontSizeSetting = std::round(size);
            }
            if (ImGui::IsItemDeactivatedAfterEdit()) ui.fontChanged = true;
        }
        ImGui::EndMenu();
    }
    if (ImGui::BeginMenu("Help")) {
        if (ImGui::MenuItem("Shortcuts", "F1")) ui.showHelp = true;
        ImGui::EndMenu();
    }
    // Right side: level name and mode.
    const std::string title = levelLabel(ed);
    const char* mode = ed.sim.state() == SimState::Playing ? "PLAYING" : ed.sim.state() == SimState::Paused ? "PAUSED" : "EDIT";
    const float w = ImGui::CalcTextSize(title.c_str()).x + ImGui::CalcTextSize(mode).x + 40 * ui.scale;
    ImGui::SameLine(ImGui::GetWindowWidth() - w);
    ImGui::TextColored(kDim, "%s", title.c_str());
    ImGui::SameLine();
    ImGui::TextColored(ed.sim.state() == SimState::Playing ? kGreen : ed.sim.state() == SimState::Paused ? kGold : kAccent,
                       "%s", mode);
    ImGui::EndMainMenuBar();
}

// ---- tools ---------------------------------------------------------------------

void toolsPanel(UiState& ui, Editor& ed, const PanelRects& r) {
    if (!ui.showTools) return;
    placePanel(ui, "Tools", r.toolsPos, r.toolsSize);
    if (beginPanel("Tools", &ui.showTools)) {
        const float bw = (ImGui::GetContentRegionAvail().x - ImGui::GetStyle().ItemSpacing.x) / 2;
        for (int t = 0; t < int(Tool::Count); ++t) {
            const Tool tool = Tool(t);
            const bool active = ed.tool == tool;
            if (active) ImGui::PushStyleColor(ImGuiCol_Button, ImGui::GetStyleColorVec4(ImGuiCol_HeaderActive));
            const std::string label = std::to_string((t + 1) % 10) + "  " + std::string(editor::toolName(tool));
            if (ImGui::Button(label.c_str(), ImVec2(bw, 0))) {
                ed.tool = tool;
            }
            if (active) ImGui::PopStyleColor();
            if (t % 2 == 0 && t + 1 < int(Tool::Count)) ImGui::SameLine();
        }
        if (ed.tool == Tool::Polygon) {
            // Click the vertices (their convex hull), or drag a regular n-gon.
            static const char* kShapes[] = {"click vertices", "", "", "triangle", "square", "pentagon",
                                            "hexagon", "heptagon", "octagon"};
            ImGui::SetNextItemWidth(-1);
            if (ImGui::BeginCombo("##polygon", kShapes[ed.polygonSides])) {
                for (int n : {0, 3, 4, 5, 6, 7, 8})
                    if (ImGui::Selectable(kShapes[n], ed.polygonSides == n)) {
                        ed.polygonSides = n;
                        ed.cancelPolygon();
                    }
                ImGui::EndCombo();
            }
            ImGui::TextColored(kDim, ed.polygonSides == 0 ? "Click vertices; Enter or right click ends"
                                                          : "Drag from the centre out to a vertex");
        }
        ImGui::Separator();
        ImGui::Checkbox("Snap (G)", &ed.snap);
        ImGui::SameLine();
        ImGui::SetNextItemWidth(-1);
        ImGui::DragScalar("##snap", ImGuiDataType_Double, &ed.snapSpacing, 0.01f, nullptr, nullptr, "%.3g m");
        ed.snapSpacing = std::max(ed.snapSpacing, 1e-3);
        ImGui::TextColored(kDim, "Overlays");
        int i = 0;
        for (const auto& [name, overlay] : render::overlayNames()) {
            bool on = ed.overlays.has(overlay);
            if (ImGui::Checkbox(std::string(name).c_str(), &on))
                ed.overlays.bits = on ? ed.overlays.bits | std::uint32_t(overlay) : ed.overlays.bits & ~std::uint32_t(overlay);
            if (++i % 2 == 1) ImGui::SameLine(bw + ImGui::GetStyle().ItemSpacing.x + ImGui::GetStyle().WindowPadding.x);
        }
        if (ed.tool == Tool::Joint) {
            ImGui::SetNextItemWidth(-1);
            if (ImGui::BeginCombo("##jointtype", ed.jointType.c_str())) {
                for (std::string_view type : jointTypeNames())
                    if (ImGui::Selectable(std::string(type).c_str(), ed.jointType == type)) ed.jointType = std::string(type);
                ImGui::EndCombo();
            }
            ImGui::TextWrapped("%s", ed.springStart().isNull()
                                         ? "Click a body, then a second body or empty space (the world) at the anchor."
                                         : "Now click the other body or empty space, at the anchor (Esc cancels).");
        }
        if (ed.tool == Tool::Spring)
            ImGui::TextWrapped("%s", ed.springStart().isNull() ? "Click a body, then a second body or empty space."
                                                               : "Now click the other end (Esc cancels).");
    }
    ImGui::End();
}

// ---- entity list ------------------------------------------------------------------

void entitiesPanel(UiState& ui, Editor& ed, const PanelRects& r) {
    if (!ui.showEntities) return;
    placePanel(ui, "Entities", r.entitiesPos, r.entitiesSize);
    if (beginPanel("Entities", &ui.showEntities)) {
        const Registry& reg = ed.doc.scene.registry;
        ImGui::SetNextItemWidth(-1);
        ImGui::InputTextWithHint("##filter", "filter by name or type", &ui.entityFilter);
        std::vector<Entity> shown;
        shown.reserve(reg.size());
        for (Entity e : reg.entities()) {
            if (!ui.entityFilter.empty()) {
                const std::string name = editor::displayName(reg, e);
                const Type* t = reg.tryGet<Type>(e);
                if (name.find(ui.entityFilter) == std::string::npos &&
                    !(t && t->value.find(ui.entityFilter) != std::string::npos))
                    continue;
            }
            shown.push_back(e);
        }
        ImGui::TextColored(kDim, "%zu of %zu, %zu selected", shown.size(), reg.size(), ed.selection.size());
        ImGui::BeginChild("list");
        ImGuiListClipper clipper;
        clipper.Begin(int(shown.size()));
        while (clipper.Step())
            for (int i = clipper.DisplayStart; i < clipper.DisplayEnd; ++i) {
                const Entity e = shown[std::size_t(i)];
                const bool selected = std::find(ed.selection.begin(), ed.selection.end(), e) != ed.selection.end();
                const char* kind = reg.has<Spring>(e) ? "spring" : reg.has<Plane>(e) ? "wall"
                                 : reg.has<Box>(e) ? "box" : reg.has<Radius>(e) ? "circle"
                                 : reg.has<Attractor>(e) ? "attractor" : reg.has<Boid>(e) ? "boid" : "point";
                ImGui::PushID(int(e.index));
                const std::string label = editor::displayName(reg, e);
                if (ImGui::Selectable(label.c_str(), selected)) {
                    if (ed.referencePick) {
                        ed.finishReferencePick(e);  // the inspector asked for a body: this is the answer
                    } else if (ImGui::GetIO().KeyCtrl || ImGui::GetIO().KeyShift) {
                        if (selected) std::erase(ed.selection, e);
                        else ed.selection.push_back(e);
                    } else {
                        ed.select({e});
                    }
                }
                ImGui::SameLine(ImGui::GetContentRegionAvail().x - 60 * ui.scale + ImGui::GetCursorPosX() * 0);
                ImGui::TextColored(kDim, "%s", kind);
                ImGui::PopID();
            }
        ImGui::EndChild();
    }
    ImGui::End();
}

// ---- viewport ------------------------------------------------------------------------

void simToolbar(UiState& ui, Editor& ed) {
    const SimState s = ed.sim.state();
    if (ImGui::Button(s == SimState::Playing ? "Pause" : "Play")) ed.togglePlay();
    ImGui::SameLine();
    if (ImGui::Button("Step")) ed.stepForward();
    ImGui::SameLine();
    ImGui::BeginDisabled(ed.sim.historySize() == 0);
    if (ImGui::Button("Back")) ed.stepBack();
    ImGui::EndDisabled();
    ImGui::SameLine();
    ImGui::BeginDisabled(!ed.sim.running());
    if (ImGui::Button("Reset")) ed.resetSimulation();
    ImGui::EndDisabled();
    ImGui::SameLine();
    float scale = float(ed.sim.timeScale);
    // The value is written beside the slider: inside it, the handle sat on
    // top of the digits.
    ImGui::SetNextItemWidth(80 * ui.scale);
    if (ImGui::SliderFloat("##timescale", &scale, 0.05f, 4.0f, "", ImGuiSliderFlags_Logarithmic))
        ed.sim.timeScale = scale;
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Simulated seconds per real second (Ctrl+click to type)");
    ImGui::SameLine(0, 4 * ui.scale);
    ImGui::Text("time x%.2f", ed.sim.timeScale);
    ImGui::SameLine();
    bool breakOn = !ed.sim.breakOnContact.isNull();
    const bool canBreak = ed.selection.size() == 1;
    ImGui::BeginDisabled(!canBreak && !breakOn);
    if (ImGui::Checkbox("Break on contact", &breakOn))
        ed.sim.breakOnContact = breakOn && canBreak ? ed.selection[0] : Entity{};
    ImGui::EndDisabled();
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
        ImGui::SetTooltip("Pause at the step where the selected body first touches something");
    ImGui::SameLine();
    ImGui::TextColored(kDim, "t = %.3f s  step %llu  history %zu", ed.doc.scene.world.time,
                       static_cast<unsigned long long>(ed.sim.steps()), ed.sim.historySize());
}

void viewportPanel(UiState& ui, Editor& ed, const PanelRects& r) {
    placePanel(ui, "Viewport", r.viewportPos, r.viewportSize);
    ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0, 0));
    // The scene is drawn into the window before ImGui (Session::frame), so
    // this panel has no background of its own, and it stays behind every
    // other panel: one that went behind it would be drawn over the scene.
    const bool open = ImGui::Begin("Viewport", nullptr, ImGuiWindowFlags_NoScrollbar | ImGuiWindowFlags_NoScrollWithMouse |
                                                             ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoBackground |
                                                             ImGuiWindowFlags_NoBringToFrontOnFocus);
    ImGui::PopStyleVar();
    if (open) {
        // The toolbar band gets the background the window does not draw:
        // its size is known after the toolbar, so the fill goes into a
        // channel drawn under the toolbar's widgets.
        ImDrawList* dl = ImGui::GetWindowDrawList();
        dl->ChannelsSplit(2);
        dl->ChannelsSetCurrent(1);
        const ImVec2 band = ImGui::GetCursorScreenPos();
        ImGui::SetCursorPos(ImVec2(ImGui::GetCursorPosX() + 6 * ui.scale, ImGui::GetCursorPosY() + 4 * ui.scale));
        simToolbar(ui, ed);
        ImGui::SetCursorPosY(ImGui::GetCursorPosY() + 2 * ui.scale);
        ImVec2 avail = ImGui::GetContentRegionAvail();
        avail.x = std::max(16.0f, std::floor(avail.x));
        avail.y = std::max(16.0f, std::floor(avail.y));
        const ImVec2 pos = ImGui::GetCursorScreenPos();
        dl->ChannelsSetCurrent(0);
        dl->AddRectFilled(band, ImVec2(band.x + ImGui::GetWindowWidth(), std::floor(pos.y)), ImGui::GetColorU32(ImGuiCol_WindowBg));
        dl->ChannelsMerge();
        ui.viewportPos = ImVec2(std::floor(pos.x), std::floor(pos.y));
        ui.viewportSize = avail;
        // An invisible button owns the mouse over the image, so a drag there
        // is a tool's drag and never moves the window.
        ImGui::InvisibleButton("##scene", avail,
                               ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight |
                                   ImGuiButtonFlags_MouseButtonMiddle);
        ui.viewportHovered = ImGui::IsItemHovered() || ImGui::IsItemActive();
        const ImVec2 o = ui.viewportPos;
        // Mode frame: green while playing, gold when paused.
        if (ed.sim.running())
            dl->AddRect(o, ImVec2(o.x + avail.x, o.y + avail.y),
                        ImGui::GetColorU32(ed.sim.state() == SimState::Playing ? kGreen : kGold), 0, 0, 2.0f * ui.scale);
        if (auto rect = ed.selectionRect()) {
            const ImVec2 a(o.x + float(rect->first.x), o.y + float(rect->first.y));
            const ImVec2 b(o.x + float(rect->second.x), o.y + float(rect->second.y));
            dl->AddRectFilled(a, b, IM_COL32(90, 160, 240, 40));
            dl->AddRect(a, b, IM_COL32(90, 160, 240, 200));
        }
        if (!ed.springStart().isNull())
            if (const Position* p = ed.doc.scene.registry.tryGet<Position>(ed.springStart())) {
                const Vec2 a = ed.view.toPixels(p->value), b = ed.mouseViewport();
                dl->AddLine(ImVec2(o.x + float(a.x), o.y + float(a.y)), ImVec2(o.x + float(b.x), o.y + float(b.y)),
                            ImGui::GetColorU32(kGold), 1.5f * ui.scale);
            }
        // Cursor readout, bottom right of the viewport.
        const Vec2 w = ed.view.toWorld(ed.mouseViewport());
        char text[96];
        std::snprintf(text, sizeof text, "%s  x %.3f  y %.3f m%s", std::string(editor::toolName(ed.tool)).c_str(), w.x, w.y,
                      ed.snap ? "  [snap]" : "");
        const ImVec2 ts = ImGui::CalcTextSize(text);
        dl->AddText(ImVec2(o.x + avail.x - ts.x - 8 * ui.scale, o.y + avail.y - ts.y - 6 * ui.scale),
                    ImGui::GetColorU32(kDim), text);
        if (!ed.sim.message().empty() && ed.sim.running()) {
            const ImVec4 col = ed.sim.diverged() ? kRed : kGold;
            dl->AddText(ImVec2(o.x + 10 * ui.scale, o.y + avail.y - ts.y - 6 * ui.scale), ImGui::GetColorU32(col),
                        ed.sim.message().c_str());
        }
    }
    ImGui::End();
}

// ---- world panel ---------------------------------------------------------------------

void worldPanel(UiState& ui, Editor& ed, const PanelRects& r) {
    if (!ui.showWorld) return;
    placePanel(ui, "World", r.worldPos, r.worldSize);
    if (beginPanel("World", &ui.showWorld)) {
        WorldSettings ws = ed.doc.scene.world;
        auto edited = [&](const char* label) {
            // One merge key per widget activation: a drag is one undo step.
            const ImGuiID id = ImGui::GetID(label);
            if (ImGui::IsItemActivated() || ui.activeWidget != id) {
                ui.activeWidget = id;
                ui.activeKey = ed.newMergeKey();
            }
            ed.applyEdit(std::string("world: ") + label, [&](Scene& s) {
                s.world = ws;
                return true;
            }, ui.activeKey);
        };
        auto done = [&] {
            if (ImGui::IsItemDeactivated()) ed.endEdit();
        };
        ImGui::PushItemWidth(-110 * ui.scale);
        double g[2] = {ws.gravity.x, ws.gravity.y};
        if (ImGui::DragScalarN("gravity [m/s2]", ImGuiDataType_Double, g, 2, 0.05f, nullptr, nullptr, "%.4g")) {
            ws.gravity = {g[0], g[1]};
            if (isFinite(ws.gravity)) edited("gravity");
        }
        done();
        if (ImGui::DragScalar("G [N m2/kg2]", ImGuiDataType_Double, &ws.G, 0.01f, nullptr, nullptr, "%.6g") &&
            std::isfinite(ws.G))
            edited("G");
        done();
        if (ImGui::BeginCombo("integrator", ws.integrator.c_str())) {
            for (std::string_view name : integratorNames()) {
                const std::string n(name);
                if (ImGui::Selectable(n.c_str(), n == ws.integrator)) {
                    ws.integrator = n;
                    ui.activeWidget = 0;
                    ed.applyEdit("integrator " + n, [&](Scene& s) {
                        s.world.integrator = n;
                        return true;
                    });
                }
            }
            ImGui::EndCombo();
        }
        const World* world = panelWorld(ui, ed);
        if (world) {
            const std::vector<StiffnessHint> hints = world->stiffnessHints();
            if (hints.empty()) {
                ImGui::TextColored(kGreen, "stable: no spring past %s's limit", ws.integrator.c_str());
            } else {
                ImGui::TextColored(kRed, "stiff: %zu spring(s) past the limit", hints.size());
                if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", hints.front().message().c_str());
                ImGui::PushTextWrapPos(0.0f);
                ImGui::TextColored(kDim, "%s", hints.front().message().c_str());
                ImGui::PopTextWrapPos();
            }
        } else if (!ui.previewError.empty() && !ed.sim.running()) {
            ImGui::PushTextWrapPos(0.0f);
            ImGui::TextColored(kGold, "not simulable: %s", ui.previewError.c_str());
            ImGui::PopTextWrapPos();
        }
        const double dtMin = 1e-6, dtMax = 1.0;
        if (ImGui::DragScalar("dt [s]", ImGuiDataType_Double, &ws.dt, 0.0001f, &dtMin, &dtMax, "%.6g")) edited("dt");
        done();
        // 0: the level gives none and the engine chooses (shown as "auto");
        // dragging gives it a value, which the level then keeps.
        if (ImGui::DragInt("substeps", &ws.substeps, 0.1f, 1, 1000, ws.substeps == 0 ? "auto" : "%d")) {
            ws.substeps = std::clamp(ws.substeps, 1, 1000);
            edited("substeps");
        }
        done();
        if (ImGui::DragInt("solver iterations", &ws.solverIterations, 0.1f, 1, 200,
                           ws.solverIterations == 0 ? "auto" : "%d")) {
            ws.solverIterations = std::clamp(ws.solverIterations, 1, 200);
            edited("solver iterations");
        }
        done();
        // Error control (dopri5) and Barnes–Hut (attractors): shown when the
        // scene uses them.
        if (ws.integrator == "dopri5") {
            const double tolMin = 1e-14, tolMax = 1e-1;
            if (ImGui::DragScalar("tolerance", ImGuiDataType_Double, &ws.tolerance, 0.01f, &tolMin, &tolMax, "%.1e",
                                  ImGuiSliderFlags_Logarithmic))
                edited("tolerance");
            done();
            if (world) {
                const StepStats& st = world->lastStats();
                ImGui::TextColored(kDim, "internal steps %d, rejected %d (last frame)", st.internalSteps,
                                   st.rejectedSteps);
            }
            ImGui::PushTextWrapPos(0.0f);
            ImGui::TextColored(kDim, "with contacts: error-controlled steps inside each substep (dt/substeps); "
                                     "contacts are solved at substep ends, at fixed rate");
            ImGui::PopTextWrapPos();
        }
        bool attractors = false;
        if (world)
            for (std::string_view system : world->activeSystems()) attractors = attractors || system == "attractors";
        if (attractors) {
            const double thetaMin = 0.0, thetaMax = 1.0;
            if (ImGui::DragScalar("theta (Barnes-Hut)", ImGuiDataType_Double, &ws.theta, 0.005f, &thetaMin, &thetaMax,
                                  "%.3g"))
                edited("theta");
            done();
            if (ImGui::IsItemHovered())
                ImGui::SetTooltip("opening angle: 0 sums every pair exactly; larger is faster and less exact. "
                                  "Small scenes are summed exactly whatever theta says (it is faster there)");
        }
        if (world) {
            // A pile the level's substeps cannot hold: said before playing.
            if (const std::optional<PileHint> pile = world->pileHint()) {
                ImGui::PushTextWrapPos(0.0f);
                ImGui::TextColored(kGold, "%s", pile->message().c_str());
                ImGui::PopTextWrapPos();
            }
        }
        ImGui::PopItemWidth();

        // Systems: which the scene needs, a switch each, and their cost.
        ImGui::Separator();
        ImGui::TextColored(kDim, "Systems (what this level needs)");
        std::vector<std::string> systems;
        if (world)
            for (std::string_view s : world->activeSystems()) systems.emplace_back(s);
        for (const std::string& off : ed.sim.disabledSystems)
            if (std::find(systems.begin(), systems.end(), off) == systems.end()) systems.push_back(off);
        if (ImGui::BeginTable("systems", 3, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) {
            ImGui::TableSetupColumn("on", ImGuiTableColumnFlags_WidthFixed, 24 * ui.scale);
            ImGui::TableSetupColumn("system");
            ImGui::TableSetupColumn("ms/step", ImGuiTableColumnFlags_WidthFixed, 70 * ui.scale);
            ImGui::TableHeadersRow();
            for (const std::string& s : systems) {
                ImGui::TableNextRow();
                ImGui::TableNextColumn();
                bool on = !ed.sim.disabledSystems.count(s);
                ImGui::BeginDisabled(!editor::Simulation::canDisable(s));
                if (ImGui::Checkbox(("##" + s).c_str(), &on)) {
                    if (on) ed.sim.disabledSystems.erase(s);
                    else ed.sim.disabledSystems.insert(s);
                    ed.sim.sceneChanged();
                }
                ImGui::EndDisabled();
                ImGui::TableNextColumn();
                ImGui::TextUnformatted(s.c_str());
                ImGui::TableNextColumn();
                // Force systems are timed one by one; collisions is the sum
                // of the stages after the integrator (broad phase, narrow
                // phase, solver ...).
                double ms = -1.0;
                if (auto it = ui.stageAverage.find("system:" + s); it != ui.stageAverage.end()) ms = it->second;
                else if (s == "collisions")
                    for (const auto& [key, avg] : ui.stageAverage)
                        if (key.rfind("stage:", 0) == 0 && key != "stage:forces" && key != "stage:integrate" &&
                            key != "stage:rotation" && key != "stage:check")
                            ms = std::max(ms, 0.0) + avg;
                if (ui.deterministic || ms < 0.0) ImGui::TextColored(kDim, "-");
                else ImGui::Text("%.3f", ms);
            }
            ImGui::EndTable();
        }
        if (systems.empty()) ImGui::TextColored(kDim, "none (nothing moves)");
    }
    ImGui::End();
}

// ---- debug: contacts, plots, profile, history ---------------------------------------------

void contactsTab(UiState& ui, Editor& ed) {
    const World* w = ed.sim.world();
    if (!w) {
        ImGui::TextColored(kDim, "Contacts appear while the simulation runs (Space plays, Right steps).");
        return;
    }
    const auto contacts = w->contacts();
    const Registry& reg = ed.doc.scene.registry;
    ImGui::Text("%zu contacts this step", contacts.size());
    ImGui::SameLine();
    ImGui::SetNextItemWidth(180 * ui.scale);
    ImGui::InputTextWithHint("##contactfilter", "filter by body name", &ui.contactFilter);
    ImGui::SameLine();
    ImGui::TextColored(kDim, "(?)");
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("normal: unit, from a to b. depth > 0: the shapes overlap by that much; depth < 0: a gap "
                          "(a speculative contact, not touching yet).\nimpulse: normal and tangent (friction) "
                          "impulse the solver applied this step. The pair that stopped the run is in red.");
    if (contacts.empty()) return;
    // Rows shown: filtered by name, in the order the header asks for.
    std::vector<std::size_t> rows;
    for (std::size_t i = 0; i < contacts.size(); ++i) {
        if (!ui.contactFilter.empty()) {
            const ContactRecord& c = contacts[i];
            const bool match = editor::displayName(reg, c.a).find(ui.contactFilter) != std::string::npos ||
                               (reg.alive(c.b) && editor::displayName(reg, c.b).find(ui.contactFilter) != std::string::npos);
            if (!match) continue;
        }
        rows.push_back(i);
    }
    if (ImGui::BeginTable("contacts", 7, ImGuiTableFlags_RowBg | ImGuiTableFlags_ScrollY | ImGuiTableFlags_Borders |
                                             ImGuiTableFlags_Resizable | ImGuiTableFlags_Sortable)) {
        ImGui::TableSetupScrollFreeze(0, 1);
        for (const char* h : {"a", "b", "point [m]", "normal", "depth [m]", "normal impulse [N s]", "tangent impulse [N s]"})
            ImGui::TableSetupColumn(h);
        ImGui::TableHeadersRow();
        if (const ImGuiTableSortSpecs* sort = ImGui::TableGetSortSpecs(); sort && sort->SpecsCount > 0) {
            const int column = sort->Specs[0].ColumnIndex;
            const bool descending = sort->Specs[0].SortDirection == ImGuiSortDirection_Descending;
            auto key = [&](std::size_t i) -> double {
                const ContactRecord& c = contacts[i];
                switch (column) {
                case 2: return c.point.x;
                case 3: return c.normal.y;
                case 4: return c.depth;
                case 5: return c.normalImpulse;
                case 6: return c.tangentImpulse;
                default: return 0.0;
                }
            };
            std::stable_sort(rows.begin(), rows.end(), [&](std::size_t x, std::size_t y) {
                if (column <= 1) {
                    const Entity ex = column == 0 ? contacts[x].a : contacts[x].b;
                    const Entity ey = column == 0 ? contacts[y].a : contacts[y].b;
                    const std::string nx = reg.alive(ex) ? editor::displayName(reg, ex) : std::string();
                    const std::string ny = reg.alive(ey) ? editor::displayName(reg, ey) : std::string();
                    return descending ? ny < nx : nx < ny;
                }
                return descending ? key(y) < key(x) : key(x) < key(y);
            });
        }
        ImGuiListClipper clipper;
        clipper.Begin(int(rows.size()));
        while (clipper.Step())
            for (int i = clipper.DisplayStart; i < clipper.DisplayEnd; ++i) {
                const ContactRecord& c = contacts[rows[std::size_t(i)]];
                ImGui::TableNextRow();
                if (const auto& broke = ed.sim.contactPair;
                    broke && ((broke->first == c.a && broke->second == c.b) || (broke->first == c.b && broke->second == c.a)))
                    ImGui::TableSetBgColor(ImGuiTableBgTarget_RowBg1, IM_COL32(150, 50, 45, 160));
                ImGui::TableNextColumn();
                const bool selected = std::find(ed.selection.begin(), ed.selection.end(), c.a) != ed.selection.end() &&
                                      (c.b.isNull() || std::find(ed.selection.begin(), ed.selection.end(), c.b) != ed.selection.end());
                ImGui::PushID(i);
                if (ImGui::Selectable(editor::displayName(reg, c.a).c_str(), selected, ImGuiSelectableFlags_SpanAllColumns)) {
                    std::vector<Entity> pair{c.a};
                    if (reg.alive(c.b)) pair.push_back(c.b);
                    ed.select(pair);
                }
                ImGui::PopID();
                ImGui::TableNextColumn();
                ImGui::TextUnformatted(reg.alive(c.b) ? editor::displayName(reg, c.b).c_str() : "-");
                ImGui::TableNextColumn();
                ImGui::Text("%.3f, %.3f", c.point.x, c.point.y);
                ImGui::TableNextColumn();
                ImGui::Text("%.2f, %.2f", c.normal.x, c.normal.y);
                ImGui::TableNextColumn();
                ImGui::Text("%.4g", c.depth);
                ImGui::TableNextColumn();
                ImGui::Text("%.4g", c.normalImpulse);
                ImGui::TableNextColumn();
                ImGui::Text("%.4g", c.tangentImpulse);
            }
        ImGui::EndTable();
    }
}

void plotsTab(UiState& ui, Editor& ed) {
    const auto& samples = ed.sim.samples();
    if (samples.empty()) {
        ImGui::TextColored(kDim, "Energy, momentum and contacts are plotted while the simulation runs.");
        return;
    }
    const std::size_t n = std::min<std::size_t>(samples.size(), 600);
    const std::size_t first = samples.size() - n;
    std::vector<float> ke(n), pe(n), te(n), p(n), c(n);
    for (std::size_t i = 0; i < n; ++i) {
        const editor::SimSample& s = samples[first + i];
        ke[i] = float(s.kinetic);
        pe[i] = float(s.potential);
        te[i] = float(s.total);
        p[i] = float(s.momentum);
        c[i] = float(s.contacts);
    }
    const double e0 = ed.sim.initialEnergy(), e = samples.back().total;
    const double drift = e - e0;
    // Relative to the run's energy scale: |E0| alone is meaningless when the
    // level starts at rest at the potential's zero.
    double scaleJ = std::abs(e0);
    for (const editor::SimSample& s : samples) scaleJ = std::max({scaleJ, std::abs(s.kinetic), std::abs(s.potential)});
    const double rel = scaleJ > 1e-12 ? drift / scaleJ : 0.0;
    ImGui::Text("Energy drift: %+.4g J (%+.3f%% of the energy scale %.4g J) since play", drift, 100.0 * rel, scaleJ);
    ImGui::SameLine();
    ImGui::TextColored(std::abs(rel) < 0.01 ? kGreen : std::abs(rel) < 0.1 ? kGold : kRed, "%s",
                       std::abs(rel) < 0.01 ? "good" : std::abs(rel) < 0.1 ? "drifting" : "large");
    helpMarker("Total energy (kinetic + gravity + springs + attractors) now, minus at Play. Damping, drag and "
               "collisions remove energy by design; with none of them a growing drift is the integrator's error.");
    const float width = (ImGui::GetContentRegionAvail().x - 2 * ImGui::GetStyle().ItemSpacing.x) / 3;
    const float height = std::max(40.0f, ImGui::GetContentRegionAvail().y / 2 - ImGui::GetTextLineHeightWithSpacing() - 4);
    auto plot = [&](const char* label, const std::vector<float>& v, const char* unit) {
        const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
        char overlay[96];
        std::snprintf(overlay, sizeof overlay, "%s %.4g %s", label, double(v.back()), unit);
        float a = *lo, b = *hi;
        if (b - a < 1e-9f * std::max(1.0f, std::abs(b))) {
            a -= 1.0f;
            b += 1.0f;
        }
        ImGui::PlotLines(("##" + std::string(label)).c_str(), v.data(), int(v.size()), 0, overlay, a, b, ImVec2(width, height));
    };
    plot("kinetic", ke, "J");
    ImGui::SameLine();
    plot("potential", pe, "J");
    ImGui::SameLine();
    plot("total", te, "J");
    plot("|momentum|", p, "kg m/s");
    ImGui::SameLine();
    plot("contacts", c, "");
    (void)ui;
}

void profileTab(UiState& ui, Editor& ed) {
    const World* w = ed.sim.world();
    if (!w) {
        ImGui::TextColored(kDim, "The per-stage profile fills in while the simulation runs.");
        return;
    }
    const StepStats& st = w->lastStats();
    ImGui::Text("step %llu, %d force evaluations per step, %zu contacts", static_cast<unsigned long long>(st.step),
                st.forceEvaluations, st.contactCount);
    if (ImGui::BeginTable("profile", 3, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) {
        ImGui::TableSetupColumn("stage");
        ImGui::TableSetupColumn("last ms");
        ImGui::TableSetupColumn("average ms");
        ImGui::TableHeadersRow();
        auto row = [&](const std::string& name, double last, const std::string& key) {
            ImGui::TableNextRow();
            ImGui::TableNextColumn();
            ImGui::TextUnformatted(name.c_str());
            ImGui::TableNextColumn();
            if (ui.deterministic) ImGui::TextColored(kDim, "-");
            else ImGui::Text("%.3f", last);
            ImGui::TableNextColumn();
            auto it = ui.stageAverage.find(key);
            if (ui.deterministic || it == ui.stageAverage.end()) ImGui::TextColored(kDim, "-");
            else ImGui::Text("%.3f", it->second);
        };
        for (const StageTime& s : st.stages) row(std::string(s.name), s.milliseconds, "stage:" + std::string(s.name));
        for (const StageTime& s : st.systems)
            row("  " + std::string(s.name), s.milliseconds, "system:" + std::string(s.name));
        ImGui::EndTable();
    }
}

void historyTab(Editor& ed) {
    const std::vector<std::string> labels = ed.commands.labels();
    ImGui::TextColored(kDim, "Undo history (%zu), newest last", labels.size());
    ImGui::BeginChild("history", ImVec2(ImGui::GetContentRegionAvail().x * 0.5f, 0), true);
    for (std::size_t i = 0; i < labels.size(); ++i)
        ImGui::TextColored(i < ed.commands.cursor() ? ImVec4(0.85f, 0.87f, 0.9f, 1) : kDim, "%zu  %s", i + 1, labels[i].c_str());
    ImGui::EndChild();
    ImGui::SameLine();
    ImGui::BeginChild("log", ImVec2(0, 0), true);
    for (const std::string& line : ed.log) ImGui::TextUnformatted(line.c_str());
    if (ImGui::GetScrollY() >= ImGui::GetScrollMaxY()) ImGui::SetScrollHereY(1.0f);
    ImGui::EndChild();
}

void debugPanel(UiState& ui, Editor& ed, const PanelRects& r) {
    if (!ui.showDebug) return;
    placePanel(ui, "Debug", r.debugPos, r.debugSize);
    if (beginPanel("Debug", &ui.showDebug)) {
        if (ImGui::BeginTabBar("debugtabs")) {
            const char* names[] = {"Contacts", "Plots", "Profile", "History"};
            for (int t = 0; t < 4; ++t) {
                const ImGuiTabItemFlags flags = ui.debugTab == t ? ImGuiTabItemFlags_SetSelected : 0;
                if (ImGui::BeginTabItem(names[t], nullptr, flags)) {
                    if (t == 0) contactsTab(ui, ed);
                    if (t == 1) plotsTab(ui, ed);
                    if (t == 2) profileTab(ui, ed);
                    if (t == 3) historyTab(ed);
                    ImGui::EndTabItem();
                }
            }
            ui.debugTab = -1;  // SetSelected only once
            ImGui::EndTabBar();
        }
    }
    ImGui::End();
}

// ---- status bar, help, dialogs ------------------------------------------------------------

void statusBar(UiState& ui, Editor& ed) {
    const ImGuiViewport* vp = ImGui::GetMainViewport();
    const float h = ImGui::GetFrameHeight();
    ImGui::SetNextWindowPos(ImVec2(vp->Pos.x, vp->Pos.y + vp->Size.y - h));
    ImGui::SetNextWindowSize(ImVec2(vp->Size.x, h));
    ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(8 * ui.scale, 3 * ui.scale));
    ImGui::PushStyleColor(ImGuiCol_WindowBg, ImGui::GetStyleColorVec4(ImGuiCol_MenuBarBg));
    if (ImGui::Begin("##status", nullptr, ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                                              ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                              ImGuiWindowFlags_NoBringToFrontOnFocus)) {
        const std::size_t bodies = ed.doc.scene.registry.size();
        if (ui.deterministic)
            ImGui::TextColored(kDim, "%zu entities", bodies);
        else
            ImGui::TextColored(kDim, "%zu entities | frame %.1f ms (ui %.1f, scene %.1f, physics %.1f)", bodies, ui.frameMs,
                               ui.uiMs, ui.sceneMs, ui.stepMs);
        // Big scenes (100,000 bodies: ~100 ms a frame here) stay usable but
        // slow; say so and say where the time goes, so the designer knows
        // what to switch off, and say when the simulation runs slower than
        // real time (Simulation::physicsBudgetMs).
        if (!ui.deterministic && ed.sim.state() == editor::SimState::Playing && (ui.frameMs > 50.0 || ed.sim.behind())) {
            ImGui::SameLine();
            ImGui::TextColored(kGold, "| slow: %.0f fps (physics %.0f ms, drawing %.0f ms)%s", 1000.0 / ui.frameMs, ui.stepMs,
                               ui.sceneMs, ed.sim.behind() ? ", slower than real time" : "");
        }
        ImGui::SameLine();
        ImGui::TextUnformatted(("| " + ed.status).c_str());
    }
    ImGui::End();
    ImGui::PopStyleColor();
    ImGui::PopStyleVar();
}

void helpWindow(UiState& ui) {
    if (!ui.showHelp) return;
    ImGui::SetNextWindowSize(ImVec2(520 * ui.scale, 520 * ui.scale), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowPos(ImGui::GetMainViewport()->GetCenter(), ImGuiCond_FirstUseEver, ImVec2(0.5f, 0.5f));
    if (beginPanel("Help: shortcuts", &ui.showHelp)) {
        if (ImGui::BeginTable("keys", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) {
            ImGui::TableSetupColumn("keys", ImGuiTableColumnFlags_WidthFixed, 170 * ui.scale);
            ImGui::TableSetupColumn("does");
            ImGui::TableHeadersRow();
            for (const Shortcut& s : kShortcuts) {
                ImGui::TableNextRow();
                ImGui::TableNextColumn();
                ImGui::TextColored(kGold, "%s", s.keys);
                ImGui::TableNextColumn();
                ImGui::TextWrapped("%s", s.what);
            }
            ImGui::EndTable();
        }
        ImGui::TextWrapped("Playing never loses edits: R returns to the level as it was when Play was pressed. Edits "
                           "made while paused change the running state and go away with Reset. Save writes the "
                           "edited level; File > Save simulation state writes the current state.");
    }
    ImGui::End();
}

} // namespace

std::string displayableText(const std::string& text) {
    // Typographic quotes and dashes (UTF-8 E2 80 xx) that the font has no
    // glyph for are shown as their ASCII look-alikes instead of '?'.
    const ImFont* font = ImGui::GetFont();
    std::string out;
    out.reserve(text.size());
    for (std::size_t i = 0; i < text.size(); ++i) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c == 0xE2 && i + 2 < text.size() && static_cast<unsigned char>(text[i + 1]) == 0x80) {
            const auto d = static_cast<unsigned char>(text[i + 2]);
            const ImWchar codepoint = ImWchar(0x2000 + (d & 0x3F));
            const char* ascii = d == 0x98 || d == 0x99 ? "'" : d == 0x9C || d == 0x9D ? "\"" : d == 0x93 || d == 0x94 ? "-" : nullptr;
            if (ascii && (!font || !font->FindGlyphNoFallback(codepoint))) {
                out += ascii;
                i += 2;
                continue;
            }
        }
        out += char(c);
    }
    return out;
}

namespace {

void dialogs(UiState& ui, Editor& ed) {
    using editor::UiRequest;
    switch (ed.uiRequest) {
    case UiRequest::OpenDialog: ui.openDialogRequested = true; break;
    case UiRequest::SaveAsDialog: ui.saveAsDialogRequested = true; break;
    case UiRequest::Help: ui.showHelp = !ui.showHelp; break;
    case UiRequest::ConfirmDiscard: ImGui::OpenPopup("Unsaved changes"); break;
    case UiRequest::None: break;
    }
    if (ed.uiRequest != UiRequest::ConfirmDiscard) ed.uiRequest = UiRequest::None;
    else ed.uiRequest = UiRequest::None;  // the popup is open now; pending() remembers the action

    if (ui.openDialogRequested) {
        ImGui::OpenPopup("Open level");
        ui.openDialogRequested = false;
    }
    if (ui.saveAsDialogRequested) {
        ImGui::OpenPopup("Save as");
        // An absolute suggestion in a folder that exists, wherever the
        // editor was started from.
        if (ui.saveAsPath.empty()) {
            std::error_code cwd;
            ui.saveAsPath = editor::saveAsSuggestion(ed.doc.path, ui.levelsDir, std::filesystem::current_path(cwd)).string();
        }
        ui.saveAsDialogRequested = false;
    }
    if (ui.saveStateRequested) {
        ImGui::OpenPopup("Save simulation state");
        ui.saveStateRequested = false;
    }
    const ImVec2 center = ImGui::GetMainViewport()->GetCenter();
    ImGui::SetNextWindowPos(center, ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    if (ImGui::BeginPopupModal("Unsaved changes", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        ImGui::Text("%s has unsaved changes.", ed.doc.title().c_str());
        if (ImGui::Button("Save")) {
            ed.resolvePending(Editor::Resolution::Save);
            ImGui::CloseCurrentPopup();
        }
        ImGui::SameLine();
        if (ImGui::Button("Discard")) {
            ed.resolvePending(Editor::Resolution::Discard);
            ImGui::CloseCurrentPopup();
        }
        ImGui::SameLine();
        if (ImGui::Button("Cancel") || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape))) {
            ed.resolvePending(Editor::Resolution::Cancel);
            ImGui::CloseCurrentPopup();
        }
        ImGui::EndPopup();
    }
    ImGui::SetNextWindowPos(center, ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    ImGui::SetNextWindowSize(ImVec2(520 * ui.scale, 0), ImGuiCond_Appearing);
    if (ImGui::BeginPopupModal("Open level")) {
        const std::string folder = editor::dialogFolder(ed.doc.path, ui.levelsDir).string();
        ImGui::TextColored(kDim, "Levels in %s", folder.c_str());
        ImGui::BeginChild("levels", ImVec2(0, 200 * ui.scale), true);
        for (const std::string& f : editor::levelFiles(folder))
            if (ImGui::Selectable(f.c_str(), f == ui.openPath, ImGuiSelectableFlags_AllowDoubleClick)) {
                ui.openPath = f;
                if (ImGui::IsMouseDoubleClicked(0)) {
                    ImGui::CloseCurrentPopup();
                    ed.request(editor::PendingAction::Open, ui.openPath);
                }
            }
        ImGui::EndChild();
        ImGui::SetNextItemWidth(-1);
        const bool enter = ImGui::InputTextWithHint("##path", "path/to/level.json", &ui.openPath,
                                                    ImGuiInputTextFlags_EnterReturnsTrue);
        if ((ImGui::Button("Open") || enter) && !ui.openPath.empty()) {
            ImGui::CloseCurrentPopup();
            ed.request(editor::PendingAction::Open, ui.openPath);
        }
        ImGui::SameLine();
        if (ImGui::Button("Cancel")) ImGui::CloseCurrentPopup();
        ImGui::EndPopup();
    }
    for (const char* name : {"Save as", "Save simulation state"}) {
        ImGui::SetNextWindowPos(center, ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
        ImGui::SetNextWindowSize(ImVec2(520 * ui.scale, 0), ImGuiCond_Appearing);
        if (ImGui::BeginPopupModal(name)) {
            // Type the path at once: the field takes the keyboard whenever
            // nothing else in the dialog is active (asked on the appearing
            // frame alone, the request is lost: an auto-sized window is
            // hidden on that frame).
            if (!ImGui::IsAnyItemActive()) ImGui::SetKeyboardFocusHere();
            ImGui::SetNextItemWidth(-1);
            const bool enter =
                ImGui::InputText("##saveas", &ui.saveAsPath, ImGuiInputTextFlags_EnterReturnsTrue);
            if ((ImGui::Button("Save") || enter) && !ui.saveAsPath.empty()) {
                ImGui::CloseCurrentPopup();
                if (editor::replacesAnotherFile(ui.saveAsPath, ed.doc.path)) {
                    // Another file is there: ask before writing over it.
                    ui.replaceConfirm = ui.saveAsPath;
                    ui.replaceIsState = std::string(name) != "Save as";
                } else if (std::string(name) == "Save as") {
                    ed.saveAs(ui.saveAsPath);
                } else {
                    ed.saveStateAs(ui.saveAsPath);
                }
            }
            ImGui::SameLine();
            if (ImGui::Button("Cancel")) ImGui::CloseCurrentPopup();
            ImGui::EndPopup();
        }
    }
    if (ui.replaceConfirm && !ImGui::IsPopupOpen("Replace file?")) ImGui::OpenPopup("Replace file?");
    ImGui::SetNextWindowPos(center, ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    if (ImGui::BeginPopupModal("Replace file?", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        ImGui::Text("%s already exists.", ui.replaceConfirm ? ui.replaceConfirm->c_str() : "");
        ImGui::Text("Replace it with %s?", ui.replaceIsState ? "the simulation state" : ed.doc.title().c_str());
        if (ImGui::Button("Replace")) {
            if (ui.replaceConfirm) {
                if (ui.replaceIsState) ed.saveStateAs(*ui.replaceConfirm);
                else ed.saveAs(*ui.replaceConfirm);
            }
            ui.replaceConfirm.reset();
            ImGui::CloseCurrentPopup();
        }
        ImGui::SameLine();
        if (ImGui::Button("Cancel") || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape))) {
            ed.note("not saved: " + (ui.replaceConfirm ? *ui.replaceConfirm : std::string()) + " was kept");
            ui.replaceConfirm.reset();
            ImGui::CloseCurrentPopup();
        }
        ImGui::EndPopup();
    }
    if (ui.recoveryOffer) {
        ImGui::OpenPopup("Recover unsaved changes?");
    }
    ImGui::SetNextWindowPos(center, ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    if (ImGui::BeginPopupModal("Recover unsaved changes?", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        ImGui::Text("The editor stopped before %s was saved.", ed.doc.title().c_str());
        ImGui::TextColored(kDim, "Recovery copy: %s", ui.recoveryOffer ? ui.recoveryOffer->c_str() : "");
        if (ImGui::Button("Recover")) {
            if (ui.recoveryOffer) ed.recover(*ui.recoveryOffer);
            ui.recoveryOffer.reset();
            ImGui::CloseCurrentPopup();
        }
        ImGui::SameLine();
        if (ImGui::Button("Discard it")) {
            ed.discardRecovery();
            ui.recoveryOffer.reset();
            ImGui::CloseCurrentPopup();
        }
        ImGui::EndPopup();
    }
    // A bad file (or any refused operation) gets the loader's message.
    if (!ed.errorModal.empty() && !ImGui::IsPopupOpen("Error")) ImGui::OpenPopup("Error");
    ImGui::SetNextWindowPos(center, ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    ImGui::SetNextWindowSizeConstraints(ImVec2(360 * ui.scale, 0), ImVec2(900 * ui.scale, 600 * ui.scale));
    if (ImGui::BeginPopupModal("Error", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + 640 * ui.scale);
        ImGui::TextColored(kRed, "%s", displayableText(ed.errorModal).c_str());
        ImGui::PopTextWrapPos();
        if (ImGui::Button("OK") || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Enter))) {
            ed.errorModal.clear();
            ImGui::CloseCurrentPopup();
        }
        ImGui::EndPopup();
    }
}

} // namespace

void drawEditorUi(UiState& ui, Editor& ed) {
    const ImGuiViewport* vp = ImGui::GetMainViewport();
    const PanelRects r = defaultLayout(vp->Size.x, vp->Size.y, ui.scale);
    beginLayout(ui, vp->Size);
    menuBar(ui, ed);
    toolsPanel(ui, ed, r);
    entitiesPanel(ui, ed, r);
    viewportPanel(ui, ed, r);
    if (ui.showInspector) {
        placePanel(ui, "Inspector", r.inspectorPos, r.inspectorSize);
        drawInspector(ui, ed);
    }
    worldPanel(ui, ed, r);
    debugPanel(ui, ed, r);
    statusBar(ui, ed);
    helpWindow(ui);
    dialogs(ui, ed);
    endLayout(ui, vp->Size);
}

} // namespace stepwise::ui
