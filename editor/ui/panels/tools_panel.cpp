// The Tools panel: a button per tool and the active tool's options.

#include "ui/panels/panels.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"

#include <algorithm>

namespace stepwise::ui {

using editor::Editor;
using editor::Tool;

void toolsPanel(UiState& ui, Editor& ed, const PanelRects& r) {
    if (!ui.showTools) return;
    placePanel(ui, "Tools", r.toolsPos, r.toolsSize);
    if (beginPanel("Tools", &ui.showTools)) {
        const float bw = (ImGui::GetContentRegionAvail().x - ImGui::GetStyle().ItemSpacing.x) / 2;
        for (int t = 0; t < int(Tool::Count); ++t) {
            const Tool tool = Tool(t);
            const bool active = ed.tool == tool;
            if (active) ImGui::PushStyleColor(ImGuiCol_Button, ImGui::GetStyleColorVec4(ImGuiCol_HeaderActive));
            const std::string label = std::string(editor::keyName(editor::toolKey(tool))) + "  " + std::string(editor::toolName(tool));
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
        if (ed.tool == Tool::Joint) {
            ImGui::SetNextItemWidth(-1);
            if (ImGui::BeginCombo("##jointtype", ed.jointType.c_str())) {
                for (std::string_view type : jointTypeNames())
                    if (ImGui::Selectable(std::string(type).c_str(), ed.jointType == type)) ed.jointType = std::string(type);
                ImGui::EndCombo();
            }
            recordWidgetRect(ui, "tools/jointtype");
            ImGui::TextWrapped("%s", ed.springStart().isNull()
                                         ? "Click a body, then a second body or empty space (the world) at the anchor."
                                         : "Now click the other body or empty space, at the anchor (Esc cancels).");
        }
        if (ed.tool == Tool::Spring)
            ImGui::TextWrapped("%s", ed.springStart().isNull() ? "Click a body, then a second body or empty space."
                                                               : "Now click the other end (Esc cancels).");
        // Snap and the overlays come after the tool's own options, which
        // then sit right under the tool buttons (the joint type was below
        // the fold at 1600x900, among the overlay boxes).
        ImGui::Separator();
        ImGui::Checkbox("Snap (G)", &ed.snap);
        ImGui::SameLine();
        ImGui::SetNextItemWidth(-1);
        ImGui::DragScalar("##snap", ImGuiDataType_Double, &ed.snapSpacing, 0.01f, nullptr, nullptr, "%.3g m");
        recordWidgetRect(ui, "tools/snap");
        reportRefusedTyping(ui, ed, "", "snap spacing");
        ed.snapSpacing = std::max(ed.snapSpacing, 1e-3);
        ImGui::TextColored(kDim, "Overlays");
        // Two columns when the longest label fits in half the panel, else
        // one: a label cut to "velocity-f" cannot be read.
        const ImGuiStyle& style = ImGui::GetStyle();
        float longest = 0.0f;
        for (const auto& [name, overlay] : render::overlayNames())
            longest = std::max(longest, ImGui::CalcTextSize(std::string(name).c_str()).x);
        const float boxWidth = ImGui::GetFrameHeight() + style.ItemInnerSpacing.x + longest;
        const bool twoColumns = 2 * boxWidth + style.ItemSpacing.x <= ImGui::GetContentRegionAvail().x;
        int i = 0;
        for (const auto& [name, overlay] : render::overlayNames()) {
            bool on = ed.overlays.has(overlay);
            if (ImGui::Checkbox(std::string(name).c_str(), &on))
                ed.overlays.bits = on ? ed.overlays.bits | std::uint32_t(overlay) : ed.overlays.bits & ~std::uint32_t(overlay);
            recordWidgetRect(ui, "tools/overlay/" + std::string(name));
            if (twoColumns && ++i % 2 == 1) ImGui::SameLine(bw + style.ItemSpacing.x + style.WindowPadding.x);
        }
    }
    ImGui::End();
}

} // namespace stepwise::ui
