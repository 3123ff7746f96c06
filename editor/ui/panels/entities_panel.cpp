// The Entities panel: every entity by name, click to select.

#include "ui/panels/panels.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"

#include <imgui_stdlib.h>

#include <algorithm>

namespace stepwise::ui {

using editor::Editor;

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
                    !(t && t->value.find(ui.entityFilter) != std::string::npos) &&
                    editor::entityKind(reg, e).find(ui.entityFilter) == std::string_view::npos)
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
                const std::string kind(editor::entityKind(reg, e));
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
                ImGui::TextColored(kDim, "%s", kind.c_str());
                ImGui::PopID();
            }
        ImGui::EndChild();
    }
    ImGui::End();
}

} // namespace stepwise::ui
