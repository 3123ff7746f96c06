// The Tools panel: a button per tool and the active tool's options.

#include "ui/panels/panels.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"

#include <algorithm>
#include <iterator>
#include <string>
#include <string_view>

namespace stepwise::ui {

using editor::Editor;
using editor::Tool;

namespace {

/// The overlay boxes, row by row in two columns: the per-body arrows on the
/// left, forces and the rest on the right, each name short enough for its
/// column at the default panel width (the tooltip gives the script name).
struct OverlayBox {
    render::Overlay overlay;
    const char* label;
    const char* help;
};
constexpr OverlayBox kOverlayBoxes[] = {
    {render::Overlay::Velocity, "velocity", "An arrow per moving body: its velocity."},
    {render::Overlay::Force, "force", "The applied force on each body (gravity, springs, attractors)."},
    {render::Overlay::VelocityField, "vel. field", "The moving bodies' velocity, averaged on a grid."},
    {render::Overlay::NetForce, "net force", "The net force on each body over the last step, contacts included (m dv/dt)."},
    {render::Overlay::ForceField, "force field", "The force per kilogram a body would feel, on a grid."},
    {render::Overlay::Joints, "joints", "The reaction force at each joint's anchor."},
    {render::Overlay::Contacts, "contacts", "Contact points, normals and impulses."},
    {render::Overlay::Aabb, "aabb", "Bounding boxes and the occupied cells of the broad phase's grid."},
    {render::Overlay::Trails, "trails", "Each moving body's path over the last steps."},
};

std::string_view overlayName(render::Overlay o) {
    for (const auto& [name, overlay] : render::overlayNames())
        if (overlay == o) return name;
    return "?";
}

} // namespace

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
            recordWidgetRect(ui, "tools/tool/" + std::string(editor::toolTable()[std::size_t(t)].scriptName));
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
            recordWidgetRect(ui, "tools/polygonshape");
            // Wrapped: on one line "Click vertices; Enter or right click
            // ends" was cut at the panel's edge.
            ImGui::PushStyleColor(ImGuiCol_Text, kDim);
            ImGui::TextWrapped("%s", ed.polygonSides == 0 ? "Click vertices; Enter or right click ends."
                                                          : "Drag from the centre out to a vertex.");
            ImGui::PopStyleColor();
            recordWidgetRect(ui, "tools/hint");
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
            recordWidgetRect(ui, "tools/hint");
        }
        if (ed.tool == Tool::Spring) {
            ImGui::TextWrapped("%s", ed.springStart().isNull() ? "Click a body, then a second body or empty space."
                                                               : "Now click the other end (Esc cancels).");
            recordWidgetRect(ui, "tools/hint");
        }
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
        // Two columns, the longer names on the left (the right column ends
        // where a scrollbar may be): in one column the last boxes were below
        // the fold at 1280x720. One column when the panel is too narrow for
        // two whole labels (a label cut to "velocity-f" cannot be read).
        const ImGuiStyle& style = ImGui::GetStyle();
        const float box = ImGui::GetFrameHeight() + style.ItemInnerSpacing.x;
        float left = 0.0f, right = 0.0f;
        for (std::size_t i = 0; i < std::size(kOverlayBoxes); ++i)
            (i % 2 == 0 ? left : right) = std::max(i % 2 == 0 ? left : right, ImGui::CalcTextSize(kOverlayBoxes[i].label).x);
        const float column = bw + style.ItemSpacing.x;  // under the second column of tool buttons
        const bool twoColumns = box + left + style.ItemSpacing.x <= column &&
                                column + box + right <= ImGui::GetContentRegionAvail().x;
        for (std::size_t i = 0; i < std::size(kOverlayBoxes); ++i) {
            const OverlayBox& o = kOverlayBoxes[i];
            if (twoColumns && i % 2 == 1) ImGui::SameLine(column + style.WindowPadding.x);
            bool on = ed.overlays.has(o.overlay);
            if (ImGui::Checkbox(o.label, &on))
                ed.overlays.bits = on ? ed.overlays.bits | std::uint32_t(o.overlay) : ed.overlays.bits & ~std::uint32_t(o.overlay);
            const std::string_view name = overlayName(o.overlay);
            recordWidgetRect(ui, "tools/overlay/" + std::string(name));
            if (ImGui::IsItemHovered())
                ImGui::SetTooltip("%s\n\"%.*s\" in scripts (overlay NAME on|off) and in stepwise render --overlay", o.help,
                                  int(name.size()), name.data());
        }
    }
    ImGui::End();
}

} // namespace stepwise::ui
