// The Debug panel: contacts, plots, profile and history tabs.

#include "ui/panels/panels.hpp"

#include "app/contact_rows.hpp"
#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"
#include "stepwise/integrators.hpp"

#include <imgui_stdlib.h>

#include <algorithm>
#include <deque>
#include <cmath>
#include <cstdio>

namespace stepwise::ui {

using editor::Editor;

namespace {

void helpMarker(const char* text) {
    ImGui::SameLine();
    ImGui::TextDisabled("(?)");
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", text);
}

/// Sensors: who is inside which now, and the run's events, newest first.
void sensorRows(Editor& ed) {
    const World* w = ed.sim.world();
    const std::deque<std::string>& log = ed.sim.sensorLog();
    const std::vector<std::pair<Entity, Entity>> inside = w ? w->sensorOverlaps() : std::vector<std::pair<Entity, Entity>>{};
    if (inside.empty() && log.empty()) return;
    const Registry& reg = ed.doc.scene.registry;
    if (!ImGui::CollapsingHeader(("sensors: " + std::to_string(inside.size()) + " inside, " + std::to_string(log.size()) +
                                  (log.size() == 1 ? " event" : " events") + "###sensors")
                                     .c_str(),
                                 ImGuiTreeNodeFlags_DefaultOpen))
        return;
    for (const auto& [sensor, body] : inside)
        ImGui::Text("%s is inside %s", editor::displayName(reg, body).c_str(), editor::displayName(reg, sensor).c_str());
    for (auto it = log.rbegin(); it != log.rend() && it - log.rbegin() < 8; ++it) ImGui::TextColored(kDim, "%s", it->c_str());
}

void contactsTab(UiState& ui, Editor& ed) {
    const World* w = ed.sim.world();
    if (!w) {
        ImGui::TextColored(kDim, "Contacts appear while the simulation runs (Space plays, Right steps).");
        return;
    }
    const auto contacts = ed.sim.contacts();
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
    sensorRows(ed);
    if (contacts.empty()) return;
    if (ImGui::BeginTable("contacts", 7, ImGuiTableFlags_RowBg | ImGuiTableFlags_ScrollY | ImGuiTableFlags_Borders |
                                             ImGuiTableFlags_Resizable | ImGuiTableFlags_Sortable)) {
        ImGui::TableSetupScrollFreeze(0, 1);
        for (const char* h : {"a", "b", "point [m]", "normal", "depth [m]", "normal impulse [N s]", "tangent impulse [N s]"})
            ImGui::TableSetupColumn(h);
        ImGui::TableHeadersRow();
        // Rows shown: filtered by name, in the order the header asks for.
        editor::ContactSort order;
        if (const ImGuiTableSortSpecs* sort = ImGui::TableGetSortSpecs(); sort && sort->SpecsCount > 0) {
            order.sorted = true;
            order.column = editor::ContactColumn(std::clamp(int(sort->Specs[0].ColumnIndex), 0, 6));
            order.descending = sort->Specs[0].SortDirection == ImGuiSortDirection_Descending;
        }
        const std::vector<std::size_t> rows = editor::contactRows(contacts, reg, ui.contactFilter, order);
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

} // namespace

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

} // namespace stepwise::ui
