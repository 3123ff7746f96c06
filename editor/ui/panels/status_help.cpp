// The status bar and the help window (every shortcut, once).

#include "ui/panels/panels.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"

namespace stepwise::ui {

using editor::Editor;
using editor::SimState;

namespace {

/// Every shortcut, once, for the help window (the menus show their own
/// shortcut hints; keep both in step).
struct Shortcut {
    std::string keys;
    std::string what;
};
const std::vector<Shortcut>& shortcuts() {
    static const std::vector<Shortcut> list = {
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
        {"1 .. 9, 0", "Tools: " + editor::toolHelpNames()},
        {"G", "Snap to grid on / off"},
        {"F", "Frame the whole level"},
        {"F1", "This help"},
        {"Left drag", "Select tool: move the selection, or box-select on empty space"},
        {"Shift/Ctrl+click", "Add to / remove from the selection"},
        {"Middle or right drag", "Pan"},
        {"Wheel", "Zoom about the cursor"},
        {"Left drag while playing", "Pull a body with a mouse spring"},
    };
    return list;
}

} // namespace

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
            for (const Shortcut& s : shortcuts()) {
                ImGui::TableNextRow();
                ImGui::TableNextColumn();
                ImGui::TextColored(kGold, "%s", s.keys.c_str());
                ImGui::TableNextColumn();
                ImGui::TextWrapped("%s", s.what.c_str());
            }
            ImGui::EndTable();
        }
        ImGui::TextWrapped("Playing never loses edits: R returns to the level as it was when Play was pressed. Edits "
                           "made while paused change the running state and go away with Reset. Save writes the "
                           "edited level; File > Save simulation state writes the current state.");
    }
    ImGui::End();
}

} // namespace stepwise::ui
