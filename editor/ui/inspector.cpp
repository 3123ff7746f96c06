// The inspector: one generic editor per FieldKind, driven entirely by the
// component table (names, fields, units, ranges, descriptions). Adding a
// component to the engine's table makes it editable here with no UI code.
// An edit applies to every selected entity that has the component, as one
// undo step per widget drag.

#include "ui/panels/panels.hpp"

#include "app/collision_pairs.hpp"
#include "app/scene_edit.hpp"

#include "stepwise/component_table.hpp"
#include "stepwise/components.hpp"
#include "stepwise/world_fields.hpp"

#include <imgui_internal.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace stepwise::ui {

using editor::Editor;
using editor::FieldValue;

namespace {

/// Drag speed: 0.5% of the value per pixel, at least 0.001.
float speedFor(double v) { return float(std::max(1e-3, std::abs(v) * 0.005)); }

/// The speed of a drag on the field whose widget has id `id`, holding `v`
/// now: taken from the value when the drag starts and kept for the whole
/// drag, so a drag is linear (400 px on motor_speed 1 adds 2, where a speed
/// following the value compounded 0.5% a pixel and went from 1 to -259).
float dragSpeed(UiState& ui, ImGuiID id, double v) {
    if (ImGui::GetActiveID() != id) {
        if (ui.dragSpeedFor == id) ui.dragSpeedFor = 0;  // its drag ended
        return speedFor(v);
    }
    if (ui.dragSpeedFor != id) {
        ui.dragSpeedFor = id;
        ui.dragSpeed = speedFor(v);
    }
    return ui.dragSpeed;
}

/// The id of component `i` of a DragScalarN labelled `label` (ImGui pushes
/// the label, then the index, and gives each component the label "").
ImGuiID componentId(const char* label, int i) {
    ImGui::PushID(label);
    ImGui::PushID(i);
    const ImGuiID id = ImGui::GetID("");
    ImGui::PopID();
    ImGui::PopID();
    return id;
}

/// Shows the widget for one field; returns true with `value` updated when
/// the user changed it.
bool fieldWidget(UiState& ui, const FieldInfo& f, FieldValue& value, const char* label, const Registry& reg) {
    const double* lo = std::isfinite(f.range.min) ? &f.range.min : nullptr;
    const double* hi = std::isfinite(f.range.max) ? &f.range.max : nullptr;
    switch (f.kind) {
    case FieldKind::Number: {
        double& v = std::get<double>(value);
        // A range (0, max] with a setting's own cap (dt, a tolerance,
        // joint_hz) is dragged on a log scale: its useful values span
        // decades. The level-wide bounds (1e9 for speeds, 1e30 for the rest)
        // are no such cap: a log drag across them would leap.
        if (f.range.minExclusive && f.range.min == 0.0 && hi && *hi < kMaxSpeed)
            return ImGui::DragScalar(label, ImGuiDataType_Double, &v, 0.01f, lo, hi, "%.6g",
                                     ImGuiSliderFlags_Logarithmic);
        return ImGui::DragScalar(label, ImGuiDataType_Double, &v, dragSpeed(ui, ImGui::GetID(label), v), lo, hi, "%.6g");
    }
    case FieldKind::Integer: {
        // Where 0 is below the range (substeps, solver_iterations), 0 is
        // "not given" (the engine chooses), shown as "auto" until dragged;
        // where 0 is a value (an emitter's copies so far), it shows as 0.
        int& v = std::get<int>(value);
        const int intLo = lo ? int(*lo) : 0, intHi = hi ? int(*hi) : 0;
        const bool autoAtZero = lo && *lo >= 1.0;
        if (!ImGui::DragInt(label, &v, 0.1f, intLo, intHi, v == 0 && autoAtZero ? "auto" : "%d")) return false;
        if (lo && hi) v = std::clamp(v, intLo, intHi);
        return true;
    }
    case FieldKind::OptionalNumber: {
        auto& v = std::get<std::optional<double>>(value);
        bool set = v.has_value();
        bool changed = ImGui::Checkbox((std::string("##set") + label).c_str(), &set);
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("unset: the engine's default (see the description)");
        ImGui::SameLine();
        if (changed) v = set ? std::optional<double>(lo ? std::max(*lo, 1.0) : 1.0) : std::nullopt;
        if (!v) {
            ImGui::TextColored(kDim, "%s: default", label);
            return changed;
        }
        double d = *v;
        if (ImGui::DragScalar(label, ImGuiDataType_Double, &d, dragSpeed(ui, ImGui::GetID(label), d), lo, hi, "%.6g")) {
            v = d;
            changed = true;
        }
        return changed;
    }
    case FieldKind::Vector: {
        Vec2& v = std::get<Vec2>(value);
        double xy[2] = {v.x, v.y};
        // One speed for both components (the larger's), kept while either is dragged.
        const double larger = std::max(std::abs(v.x), std::abs(v.y));
        float speed = speedFor(larger);
        for (int i = 0; i < 2; ++i) {
            const ImGuiID c = componentId(label, i);
            const float own = dragSpeed(ui, c, larger);
            if (ImGui::GetActiveID() == c) speed = own;
        }
        if (!ImGui::DragScalarN(label, ImGuiDataType_Double, xy, 2, speed, nullptr, nullptr, "%.5g"))
            return false;
        v = {xy[0], xy[1]};
        return true;
    }
    case FieldKind::OptionalVector: {
        auto& v = std::get<std::optional<Vec2>>(value);
        bool set = v.has_value();
        bool changed = ImGui::Checkbox((std::string("##set") + label).c_str(), &set);
        ImGui::SameLine();
        if (changed) v = set ? std::optional<Vec2>(Vec2{}) : std::nullopt;
        if (!v) {
            ImGui::TextColored(kDim, "%s: none", label);
            return changed;
        }
        double xy[2] = {v->x, v->y};
        if (ImGui::DragScalarN(label, ImGuiDataType_Double, xy, 2, 0.01f, nullptr, nullptr, "%.5g")) {
            v = Vec2{xy[0], xy[1]};
            changed = true;
        }
        return changed;
    }
    case FieldKind::Color: {
        Rgb& c = std::get<Rgb>(value);
        float rgb[3] = {float(c.r), float(c.g), float(c.b)};
        if (!ImGui::ColorEdit3(label, rgb, ImGuiColorEditFlags_Float)) return false;
        c = {double(std::clamp(rgb[0], 0.0f, 1.0f)), double(std::clamp(rgb[1], 0.0f, 1.0f)),
             double(std::clamp(rgb[2], 0.0f, 1.0f))};
        return true;
    }
    case FieldKind::Bool: return ImGui::Checkbox(label, &std::get<bool>(value));
    case FieldKind::Bits: {
        // Bit fields read best in hexadecimal, one digit per four bits.
        std::uint32_t& v = std::get<std::uint32_t>(value);
        return ImGui::InputScalar(label, ImGuiDataType_U32, &v, nullptr, nullptr, "%08X",
                                  ImGuiInputTextFlags_CharsHexadecimal);
    }
    case FieldKind::VectorList: {
        // One row per vertex, grouped so the whole list is one item (one
        // undo step per drag). The component's check refuses an edit that
        // would make the list invalid (a dent in a polygon).
        auto& list = std::get<std::vector<Vec2>>(value);
        bool changed = false;
        ImGui::BeginGroup();
        ImGui::TextUnformatted(label);
        for (std::size_t i = 0; i < list.size(); ++i) {
            double xy[2] = {list[i].x, list[i].y};
            const std::string row = std::to_string(i);
            if (ImGui::DragScalarN(row.c_str(), ImGuiDataType_Double, xy, 2, 0.01f, nullptr, nullptr, "%.5g")) {
                list[i] = {xy[0], xy[1]};
                changed = true;
            }
        }
        ImGui::EndGroup();
        return changed;
    }
    case FieldKind::IntegerList: {
        // Run state the engine keeps (an emitter's copies alive): shown,
        // not edited, as the names of the copies follow from it.
        const auto& list = std::get<std::vector<int>>(value);
        std::string text;
        for (const int n : list) text += (text.empty() ? "" : " ") + std::to_string(n);
        ImGui::TextColored(kDim, "%s: %s", label, text.empty() ? "-" : text.c_str());
        return false;
    }
    case FieldKind::ShapeList: {
        // One tree node per shape with its geometry and material; the whole
        // list is one value, so a drag is one undo step and the component's
        // check refuses an edit that breaks a shape.
        auto& list = std::get<std::vector<CompoundShape>>(value);
        bool changed = false;
        ImGui::BeginGroup();
        ImGui::TextUnformatted(label);
        static constexpr const char* kKinds[] = {"circle", "box", "polygon", "capsule"};
        const auto drag2 = [&](const char* name, Vec2& v) {
            double xy[2] = {v.x, v.y};
            if (!ImGui::DragScalarN(name, ImGuiDataType_Double, xy, 2, 0.01f, nullptr, nullptr, "%.5g")) return;
            v = {xy[0], xy[1]};
            changed = true;
        };
        const auto drag1 = [&](const char* name, double& d, double min) {
            if (ImGui::DragScalar(name, ImGuiDataType_Double, &d, 0.01f, &min, nullptr, "%.5g")) changed = true;
        };
        const auto optional1 = [&](const char* name, std::optional<double>& o, double fallback) {
            double d = o.value_or(fallback);
            const double min = 0.0;
            if (ImGui::DragScalar(name, ImGuiDataType_Double, &d, 0.01f, &min, nullptr, "%.5g")) {
                o = d;
                changed = true;
            }
        };
        for (std::size_t i = 0; i < list.size(); ++i) {
            CompoundShape& s = list[i];
            ImGui::PushID(int(i));
            const std::string title = std::to_string(i) + ": " + kKinds[int(s.kind)];
            if (ImGui::TreeNode(title.c_str())) {
                const double tiny = 1e-6;
                switch (s.kind) {
                case CompoundShape::Kind::Circle:
                    drag2("center", s.center);
                    drag1("radius", s.radius, tiny);
                    break;
                case CompoundShape::Kind::Box:
                    drag2("center", s.center);
                    drag1("width", s.width, tiny);
                    drag1("height", s.height, tiny);
                    drag1("angle", s.angle, -1e9);
                    break;
                case CompoundShape::Kind::Polygon:
                    for (std::size_t k = 0; k < s.vertices.size(); ++k) drag2(std::to_string(k).c_str(), s.vertices[k]);
                    break;
                case CompoundShape::Kind::Capsule:
                    drag2("a", s.a);
                    drag2("b", s.b);
                    drag1("radius", s.radius, tiny);
                    break;
                }
                optional1("density", s.density, 1.0);
                optional1("friction", s.friction, Friction{}.value);
                optional1("restitution", s.restitution, Restitution{}.value);
                bool sensor = s.sensor.value_or(false);
                if (ImGui::Checkbox("sensor", &sensor)) {
                    s.sensor = sensor;
                    changed = true;
                }
                ImGui::TreePop();
            }
            ImGui::PopID();
        }
        // Shapes are added at the body's position and removed from the end;
        // the list's check refuses removing the last one.
        for (int k = 0; k < 4; ++k) {
            if (k > 0) ImGui::SameLine();
            const std::string add = std::string("+ ") + kKinds[k];
            if (!ImGui::SmallButton(add.c_str())) continue;
            CompoundShape s;
            s.kind = CompoundShape::Kind(k);
            if (s.kind == CompoundShape::Kind::Polygon) s.vertices = Polygon{}.vertices;
            list.push_back(s);
            changed = true;
        }
        ImGui::SameLine();
        if (ImGui::SmallButton("- last") && !list.empty()) {
            list.pop_back();
            changed = true;
        }
        ImGui::EndGroup();
        return changed;
    }
    case FieldKind::String:
        if (!f.choices.empty()) {
            // A fixed set of names (a joint's type): a combo, never a typo.
            std::string& current = std::get<std::string>(value);
            bool changed = false;
            if (ImGui::BeginCombo(label, current.c_str())) {
                for (std::string_view choice : f.choices)
                    if (ImGui::Selectable(std::string(choice).c_str(), current == choice)) {
                        current = std::string(choice);
                        changed = true;
                    }
                ImGui::EndCombo();
            }
            return changed;
        }
        return ImGui::InputText(label, &std::get<std::string>(value));
    case FieldKind::EntityRef: {
        // Chosen from the bodies, never typed: the field holds a handle, so
        // renaming the body later keeps the reference.
        Entity& ref = std::get<Entity>(value);
        const std::string current = ref.isNull() ? std::string("(none)") : editor::displayName(reg, ref);
        bool changed = false;
        if (ImGui::BeginCombo(label, current.c_str(), ImGuiComboFlags_HeightLarge)) {
            if (ImGui::Selectable("(none)", ref.isNull())) {
                ref = {};
                changed = true;
            }
            for (Entity e : reg.entities()) {
                if (!editor::isBody(reg, e)) continue;
                ImGui::PushID(int(e.index));
                if (ImGui::Selectable(editor::displayName(reg, e).c_str(), e == ref)) {
                    ref = e;
                    changed = true;
                }
                ImGui::PopID();
            }
            ImGui::EndCombo();
        }
        return changed;
    }
    }
    return false;
}

/// "key [unit]", the label of a field's widget.
std::string fieldLabel(std::string_view key, std::string_view unit) {
    std::string label(key);
    if (!unit.empty()) label += " [" + std::string(unit) + "]";
    return label;
}

} // namespace

void reportRefusedTyping(UiState& ui, Editor& ed, const std::string& who, std::string_view field) {
    if (ui.refusedTypingFor == 0 || !ImGui::IsItemActive() || GImGui->LastItemData.ID != ui.refusedTypingFor) return;
    const std::string text = "refused: " + who + std::string(field) + ": \"" + ui.refusedTyping +
                             "\" is not a number (digits, '.', 'e', '+', '-', '*' and '/' can be typed)";
    if (ed.status != text) ed.note(text, true);
}

bool worldFieldWidget(UiState& ui, Editor& ed, std::string_view key) {
    const WorldFieldInfo* info = findWorldField(key);
    if (!info) return false;
    const FieldInfo& f = info->field;
    FieldValue value = editor::readField(f, &ed.doc.scene.world);
    const std::string label = fieldLabel(f.key, f.unit);
    const bool changed = fieldWidget(ui, f, value, label.c_str(), ed.doc.scene.registry);
    recordWidgetRect(ui, "world/" + std::string(key));
    reportRefusedTyping(ui, ed, "world.", f.key);
    if (ImGui::IsItemHovered() && !f.description.empty())
        ImGui::SetTooltip("%.*s%s%s", int(f.description.size()), f.description.data(),
                          f.kind == FieldKind::Number || f.kind == FieldKind::Integer ? "\nrange: " : "",
                          f.kind == FieldKind::Number || f.kind == FieldKind::Integer
                              ? f.range.describe(f.kind == FieldKind::Integer).c_str()
                              : "");
    if (changed) {
        // One merge key per widget activation: a drag is one undo step.
        const ImGuiID id = ImGui::GetID(label.c_str());
        if (ImGui::IsItemActivated() || ui.activeWidget != id) {
            ui.activeWidget = id;
            ui.activeKey = ed.newMergeKey();
        }
        std::optional<Error> problem;
        if (!ed.applyEdit("world: " + std::string(f.key), [&](Scene& s) {
                problem = editor::setWorldField(s, *info, value);
                return !problem;
            }, ui.activeKey) &&
            problem)
            ed.refuse(problem->message);
    }
    if (ImGui::IsItemDeactivated()) ed.endEdit();
    return changed;
}

/// What the selected body never collides with (filters, joints), so a
/// designer sees the effect of a filter without running the level.
void drawExcludedPartners(const Scene& scene, Entity body) {
    const std::vector<editor::ExcludedPartner> excluded = editor::excludedPartners(scene, body);
    if (excluded.empty()) return;
    const std::string header = "never collides with (" + std::to_string(excluded.size()) + ")";
    if (!ImGui::CollapsingHeader(header.c_str())) return;
    constexpr std::size_t kListed = 20;
    for (std::size_t i = 0; i < excluded.size() && i < kListed; ++i)
        ImGui::TextColored(kDim, "%s  (%s)", editor::displayName(scene.registry, excluded[i].body).c_str(),
                           excluded[i].reason.c_str());
    if (excluded.size() > kListed) ImGui::TextColored(kDim, "... and %zu more", excluded.size() - kListed);
}

void drawInspector(UiState& ui, Editor& ed) {
    if (!beginPanel("Inspector", &ui.showInspector)) {
        ImGui::End();
        return;
    }
    Registry& reg = ed.doc.scene.registry;
    if (ed.selection.empty()) {
        ImGui::TextColored(kDim, "Nothing selected.");
        ImGui::TextWrapped("Click a body in the viewport or the entity list; shift-click or drag a box for several. "
                           "Place new ones with the tools (1-9, 0).");
        ImGui::End();
        return;
    }
    const Entity primary = ed.selection.front();
    const std::vector<Entity> selection = ed.selection;
    if (selection.size() == 1) ImGui::Text("%s", editor::displayName(reg, primary).c_str());
    else ImGui::Text("%zu selected (edits apply to all that have the component)", selection.size());
    ImGui::Separator();

    const ComponentInfo* toRemove = nullptr;
    for (const ComponentInfo& info : componentTable()) {
        std::size_t having = 0;
        Entity first;
        for (Entity e : selection)
            if (info.has(reg, e)) {
                if (!having) first = e;
                ++having;
            }
        if (!having) continue;
        ImGui::PushID(info.name.data());
        const std::string header = std::string(info.name) +
                                   (having < selection.size() ? " (" + std::to_string(having) + " of " +
                                                                    std::to_string(selection.size()) + ")"
                                                              : "");
        const bool open = ImGui::CollapsingHeader(header.c_str(), ImGuiTreeNodeFlags_DefaultOpen | ImGuiTreeNodeFlags_AllowItemOverlap);
        if (ImGui::IsItemHovered() && !info.description.empty())
            ImGui::SetTooltip("%.*s", int(info.description.size()), info.description.data());
        ImGui::SameLine(ImGui::GetContentRegionMax().x - ImGui::GetFrameHeight());
        if (ImGui::SmallButton("x")) toRemove = &info;
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("Remove %.*s", int(info.name.size()), info.name.data());
        if (open) {
            const void* component = info.getConst(reg, first);
            ImGui::PushItemWidth(-ImGui::GetContentRegionAvail().x * 0.38f);
            for (const FieldInfo& f : info.fields) {
                FieldValue value = editor::readField(f, component);
                // Mixed values across the selection are marked; the widget
                // shows the first entity's.
                bool mixed = false;
                for (Entity e : selection)
                    if (const void* other = info.getConst(reg, e); other && e != first)
                        mixed = mixed || !(editor::readField(f, other) == value);
                std::string label = fieldLabel(f.key.empty() ? info.name : f.key, f.unit);
                if (mixed) label += " (mixed)";
                ImGui::PushID(f.key.empty() ? "value" : f.key.data());
                const ImGuiID id = ImGui::GetID(label.c_str());
                const bool changed = fieldWidget(ui, f, value, label.c_str(), reg);
                reportRefusedTyping(ui, ed, "\"" + editor::displayName(reg, primary) + "\" ",
                                    editor::fieldPathName(info, f.key));
                {  // where the field is this frame, for --debug-state (tests click it wherever the layout puts it)
                    const ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
                    std::string key = "inspector/";
                    key += info.name;
                    if (!f.key.empty()) {
                        key += '.';
                        key += f.key;
                    }
                    ui.widgetRects[key] = ImVec4(lo.x, lo.y, hi.x - lo.x, hi.y - lo.y);
                }
                if (f.kind == FieldKind::EntityRef) {
                    ImGui::SameLine();
                    if (ImGui::SmallButton("pick")) ed.startReferencePick(info, f, selection);
                    if (ImGui::IsItemHovered())
                        ImGui::SetTooltip("Click, then click a body in the viewport or the entity list (Esc cancels)");
                }
                if (ImGui::IsItemHovered() && !f.description.empty())
                    ImGui::SetTooltip("%.*s%s%s", int(f.description.size()), f.description.data(),
                                      f.kind == FieldKind::Number ? "\nrange: " : "",
                                      f.kind == FieldKind::Number ? f.range.describe().c_str() : "");
                if (changed) {
                    if (ImGui::IsItemActivated() || ui.activeWidget != id) {
                        ui.activeWidget = id;
                        ui.activeKey = ed.newMergeKey();
                    }
                    std::string what = "edit ";
                    what += info.name;
                    if (!f.key.empty()) {
                        what += '.';
                        what += f.key;
                    }
                    const Result<bool> edited = ed.tryEdit(what, [&](Scene& s) {
                        return editor::changedAny(editor::setFieldOnAll(s, info, f, value, selection));
                    }, ui.activeKey);
                    if (!edited) ed.refuse(edited.error());
                }
                if (ImGui::IsItemDeactivated()) ed.endEdit();
                ImGui::PopID();
            }
            ImGui::PopItemWidth();
        }
        ImGui::PopID();
    }
    if (selection.size() == 1) drawExcludedPartners(ed.doc.scene, primary);
    if (toRemove) {
        const ComponentInfo& info = *toRemove;
        const Result<bool> edited = ed.tryEdit("remove " + std::string(info.name), [&](Scene& s) {
            return editor::changedAny(editor::removeComponentFromAll(s, info, selection));
        });
        if (!edited) ed.refuse(edited.error());
    }

    ImGui::Separator();
    ImGui::SetNextItemWidth(-1);
    if (ImGui::BeginCombo("##add", "Add component...")) {
        for (const ComponentInfo& info : componentTable()) {
            const bool all = std::all_of(selection.begin(), selection.end(), [&](Entity e) { return info.has(reg, e); });
            if (all) continue;
            if (ImGui::Selectable(std::string(info.name).c_str())) {
                const Result<bool> edited = ed.tryEdit("add " + std::string(info.name), [&](Scene& s) {
                    return editor::changedAny(editor::addComponentToAll(s, info, selection));
                });
                if (!edited) ed.refuse(edited.error());
            }
            if (ImGui::IsItemHovered() && !info.description.empty())
                ImGui::SetTooltip("%.*s", int(info.description.size()), info.description.data());
        }
        ImGui::EndCombo();
    }
    if (ed.statusRefused) ImGui::TextColored(kRed, "%s", ed.status.c_str());
    ImGui::End();
}

} // namespace stepwise::ui
