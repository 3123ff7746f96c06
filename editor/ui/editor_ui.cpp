#include "ui/editor_ui.hpp"

#include "ui/panels/panels.hpp"

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

PanelRects defaultLayout(float width, float height, float scale) {
    PanelRects r;
    const float menu = 13.0f * scale + 8.0f;    // menu bar: font height + frame padding
    const float status = 13.0f * scale + 10.0f;  // status bar
    float left = std::round(230.0f * scale), right = std::round(330.0f * scale);
    // A narrow window: the side panels give way so the viewport keeps 40%
    // of the width (at fixed widths, a 320 px window pushes it off the
    // right edge).
    if (width - left - right < 0.4f * width) {
        const float shrink = 0.6f * width / (left + right);
        left = std::floor(left * shrink);
        right = std::floor(right * shrink);
    }
    const float bottom = std::round(std::min(230.0f * scale, 0.3f * height));
    const float top = menu, usable = height - menu - status;
    const float centerW = width - left - right;
    // Tall enough for the tools, the active tool's options (the Joint
    // tool's are the tallest) and the overlay boxes in two columns, from a
    // 720 px window up; the entity list below scrolls.
    const float toolsH = std::round(std::min(480.0f * scale, usable * 0.56f));
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

} // namespace

void recordWidgetRect(UiState& ui, const std::string& key) {
    const ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
    ui.widgetRects[key] = ImVec4(lo.x, lo.y, hi.x - lo.x, hi.y - lo.y);
}

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

void drawEditorUi(UiState& ui, Editor& ed) {
    const ImGuiViewport* vp = ImGui::GetMainViewport();
    const PanelRects r = defaultLayout(vp->Size.x, vp->Size.y, ui.scale);
    beginLayout(ui, vp->Size);
    ui.widgetRects.clear();
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
