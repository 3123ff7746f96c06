// The main menu bar: File, Edit, View, Simulation, Help; the level title at the right.

#include "ui/panels/panels.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"

#include <cmath>

namespace stepwise::ui {

using editor::Editor;
using editor::SimState;

namespace {

std::string levelLabel(const Editor& ed) { return ed.doc.title() + (ed.dirty() ? " *" : ""); }

} // namespace

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
    std::string modeText = ed.sim.state() == SimState::Playing ? "PLAYING" : ed.sim.state() == SimState::Paused ? "PAUSED" : "EDIT";
    // Edits made while running are not in the level (no `*`): the mode says
    // how many the run holds.
    if (const std::size_t n = ed.editsSincePlay(); n > 0) modeText += " +" + std::to_string(n) + (n == 1 ? " run edit" : " run edits");
    const char* mode = modeText.c_str();
    const float w = ImGui::CalcTextSize(title.c_str()).x + ImGui::CalcTextSize(mode).x + 40 * ui.scale;
    ImGui::SameLine(ImGui::GetWindowWidth() - w);
    ImGui::TextColored(kDim, "%s", title.c_str());
    ImGui::SameLine();
    ImGui::TextColored(ed.sim.state() == SimState::Playing ? kGreen : ed.sim.state() == SimState::Paused ? kGold : kAccent,
                       "%s", mode);
    ImGui::EndMainMenuBar();
}

} // namespace stepwise::ui
