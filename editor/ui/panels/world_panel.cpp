// The World panel: world settings, systems and their costs.

#include "ui/panels/panels.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"
#include "stepwise/integrators.hpp"

#include <algorithm>
#include <cmath>

namespace stepwise::ui {

using editor::Editor;

void worldPanel(UiState& ui, Editor& ed, const PanelRects& r) {
    if (!ui.showWorld) return;
    placePanel(ui, "World", r.worldPos, r.worldSize);
    if (beginPanel("World", &ui.showWorld)) {
        const WorldSettings& ws = ed.doc.scene.world;
        // Each setting's widget, range and check come from the world-settings
        // table (worldFieldWidget); this panel only lays them out.
        ImGui::PushItemWidth(-110 * ui.scale);
        for (const char* key : {"gravity", "G", "integrator"}) worldFieldWidget(ui, ed, key);
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
        for (const char* key : {"dt", "substeps", "solver_iterations"}) worldFieldWidget(ui, ed, key);
        // Error control (dopri5) and Barnes–Hut (attractors): shown when the
        // scene uses them.
        if (ws.integrator == "dopri5") {
            worldFieldWidget(ui, ed, "tolerance");
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
            worldFieldWidget(ui, ed, "theta");
        }
        // Joint softness: shown when the scene has joints.
        bool jointed = false;
        if (world)
            for (std::string_view system : world->activeSystems()) jointed = jointed || system == "joints";
        if (jointed)
            for (const char* key : {"joint_hz", "joint_damping_ratio"}) worldFieldWidget(ui, ed, key);
        // Sleeping: the switch, its thresholds while it is on, and how many
        // bodies sleep now (drawn dimmed in the viewport).
        worldFieldWidget(ui, ed, "sleep");
        if (ws.sleep) {
            for (const char* key : {"sleep_velocity", "sleep_time"}) worldFieldWidget(ui, ed, key);
            if (world && world->bodyCount() > 0)
                ImGui::TextColored(kDim, "%zu of %zu bodies asleep (dimmed)", world->sleepingBodyCount(),
                                   world->bodyCount());
        }
        if (world) {
            // A pile, an impact or joint loops the level's substeps cannot hold: said before playing.
            if (const std::optional<PileHint> pile = world->pileHint()) {
                ImGui::PushTextWrapPos(0.0f);
                ImGui::TextColored(kGold, "%s", pile->message().c_str());
                ImGui::PopTextWrapPos();
            }
            if (const std::optional<ContactStiffnessHint> stiffness = world->contactStiffnessHint()) {
                ImGui::PushTextWrapPos(0.0f);
                ImGui::TextColored(kGold, "%s", stiffness->message().c_str());
                ImGui::PopTextWrapPos();
            }
            if (const std::optional<ImpactHint> impact = world->impactHint()) {
                ImGui::PushTextWrapPos(0.0f);
                ImGui::TextColored(kGold, "%s", impact->message().c_str());
                ImGui::PopTextWrapPos();
            }
            if (const std::optional<JointLoopHint> loops = world->jointLoopHint()) {
                ImGui::PushTextWrapPos(0.0f);
                ImGui::TextColored(kGold, "%s", loops->message().c_str());
                ImGui::PopTextWrapPos();
            }
            if (const std::optional<JointSupportHint> load = world->jointSupportHint()) {
                ImGui::PushTextWrapPos(0.0f);
                ImGui::TextColored(kGold, "%s", load->message().c_str());
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

} // namespace stepwise::ui
