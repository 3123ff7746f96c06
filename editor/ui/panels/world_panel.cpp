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

} // namespace stepwise::ui
