// The Viewport panel: the simulation toolbar above the scene, which Session draws into the panel's rectangle.

#include "ui/panels/panels.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace stepwise::ui {

using editor::Editor;
using editor::SimState;

namespace {

void simToolbar(UiState& ui, Editor& ed) {
    const SimState s = ed.sim.state();
    if (ImGui::Button(s == SimState::Playing ? "Pause" : "Play")) ed.togglePlay();
    ImGui::SameLine();
    if (ImGui::Button("Step")) ed.stepForward();
    ImGui::SameLine();
    ImGui::BeginDisabled(ed.sim.historySize() == 0);
    if (ImGui::Button("Back")) ed.stepBack();
    ImGui::EndDisabled();
    ImGui::SameLine();
    ImGui::BeginDisabled(!ed.sim.running());
    if (ImGui::Button("Reset")) ed.resetSimulation();
    ImGui::EndDisabled();
    ImGui::SameLine();
    float scale = float(ed.sim.timeScale);
    // The value is written beside the slider: inside it, the handle sat on
    // top of the digits.
    ImGui::SetNextItemWidth(80 * ui.scale);
    if (ImGui::SliderFloat("##timescale", &scale, 0.05f, 4.0f, "", ImGuiSliderFlags_Logarithmic))
        ed.sim.timeScale = scale;
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Simulated seconds per real second (Ctrl+click to type)");
    ImGui::SameLine(0, 4 * ui.scale);
    ImGui::Text("time x%.2f", ed.sim.timeScale);
    ImGui::SameLine();
    // The watched body is named beside the box and chosen there; it does
    // not follow the selection (a break selects the pair it stopped at,
    // which would then change what is watched).
    bool breakOn = !ed.sim.breakOnContact.isNull();
    const Registry& reg = ed.doc.scene.registry;
    const bool canBreak = ed.selection.size() == 1 && editor::isBody(reg, ed.selection[0]);
    ImGui::BeginDisabled(!canBreak && !breakOn);
    if (ImGui::Checkbox("Break on contact", &breakOn)) ed.setBreakOnContact(breakOn && canBreak ? ed.selection[0] : Entity{});
    ImGui::EndDisabled();
    const char* breakHelp = "Pause at the step where the watched body first touches something, or is about to "
                            "(a speculative contact). Ticking the box watches the selected body; the list "
                            "picks any body. Selecting another body later does not change it.";
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) ImGui::SetTooltip("%s", breakHelp);
    ImGui::SameLine(0, 4 * ui.scale);
    ImGui::SetNextItemWidth(96 * ui.scale);
    if (ImGui::BeginCombo("##breakon", ed.breakOnLabel().c_str(), ImGuiComboFlags_HeightLarge)) {
        if (ImGui::Selectable("off", !breakOn)) ed.setBreakOnContact({});
        std::vector<Entity> bodies;
        for (Entity e : reg.entities())
            if (editor::isBody(reg, e)) bodies.push_back(e);
        ImGuiListClipper clipper;
        clipper.Begin(int(bodies.size()));
        while (clipper.Step())
            for (int i = clipper.DisplayStart; i < clipper.DisplayEnd; ++i) {
                const Entity e = bodies[std::size_t(i)];
                ImGui::PushID(int(e.index));
                if (ImGui::Selectable(editor::displayName(reg, e).c_str(), e == ed.sim.breakOnContact))
                    ed.setBreakOnContact(e);
                ImGui::PopID();
            }
        ImGui::EndCombo();
    }
    recordWidgetRect(ui, "viewport/breakon");
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", breakHelp);
    ImGui::SameLine();
    ImGui::Checkbox("Break on sensor", &ed.sim.breakOnSensor);
    recordWidgetRect(ui, "viewport/breakonsensor");
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("Pause at the step where a body enters or leaves a sensor (a shape with \"sensor\": true).");
    char clock[96];
    std::snprintf(clock, sizeof clock, "t = %.3f s  step %llu  history %zu", ed.doc.scene.world.time,
                  static_cast<unsigned long long>(ed.sim.steps()), ed.sim.historySize());
    // On the same row when it fits, else on a row of its own: cut off at
    // the panel's edge it would hide the step count.
    const float right = ImGui::GetItemRectMax().x + ImGui::GetStyle().ItemSpacing.x + ImGui::CalcTextSize(clock).x;
    if (right <= ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x) ImGui::SameLine();
    else ImGui::SetCursorPosX(ImGui::GetCursorPosX() + 6 * ui.scale);
    ImGui::TextColored(kDim, "%s", clock);
}

} // namespace

void viewportPanel(UiState& ui, Editor& ed, const PanelRects& r) {
    placePanel(ui, "Viewport", r.viewportPos, r.viewportSize);
    ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0, 0));
    // The scene is drawn into the window before ImGui (Session::frame), so
    // this panel has no background of its own, and it stays behind every
    // other panel: one that went behind it would be drawn over the scene.
    const bool open = ImGui::Begin("Viewport", nullptr, ImGuiWindowFlags_NoScrollbar | ImGuiWindowFlags_NoScrollWithMouse |
                                                             ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoBackground |
                                                             ImGuiWindowFlags_NoBringToFrontOnFocus);
    ImGui::PopStyleVar();
    if (open) {
        // The toolbar band gets the background the window does not draw:
        // its size is known after the toolbar, so the fill goes into a
        // channel drawn under the toolbar's widgets.
        ImDrawList* dl = ImGui::GetWindowDrawList();
        dl->ChannelsSplit(2);
        dl->ChannelsSetCurrent(1);
        const ImVec2 band = ImGui::GetCursorScreenPos();
        ImGui::SetCursorPos(ImVec2(ImGui::GetCursorPosX() + 6 * ui.scale, ImGui::GetCursorPosY() + 4 * ui.scale));
        simToolbar(ui, ed);
        ImGui::SetCursorPosY(ImGui::GetCursorPosY() + 2 * ui.scale);
        ImVec2 avail = ImGui::GetContentRegionAvail();
        avail.x = std::max(16.0f, std::floor(avail.x));
        avail.y = std::max(16.0f, std::floor(avail.y));
        const ImVec2 pos = ImGui::GetCursorScreenPos();
        dl->ChannelsSetCurrent(0);
        dl->AddRectFilled(band, ImVec2(band.x + ImGui::GetWindowWidth(), std::floor(pos.y)), ImGui::GetColorU32(ImGuiCol_WindowBg));
        dl->ChannelsMerge();
        ui.viewportPos = ImVec2(std::floor(pos.x), std::floor(pos.y));
        ui.viewportSize = avail;
        // An invisible button owns the mouse over the image, so a drag there
        // is a tool's drag and never moves the window.
        ImGui::InvisibleButton("##scene", avail,
                               ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight |
                                   ImGuiButtonFlags_MouseButtonMiddle);
        ui.viewportHovered = ImGui::IsItemHovered() || ImGui::IsItemActive();
        const ImVec2 o = ui.viewportPos;
        // Mode frame: green while playing, gold when paused.
        if (ed.sim.running())
            dl->AddRect(o, ImVec2(o.x + avail.x, o.y + avail.y),
                        ImGui::GetColorU32(ed.sim.state() == SimState::Playing ? kGreen : kGold), 0, 0, 2.0f * ui.scale);
        // While the simulation runs, edits change the running state, not
        // the level: said at the top of the scene, over a dark band.
        if (const std::string note = ed.runningEditsNote(); !note.empty()) {
            const ImVec2 ts = ImGui::CalcTextSize(note.c_str());
            const float pad = 4 * ui.scale;
            const ImVec2 at(o.x + 8 * ui.scale, o.y + 6 * ui.scale);
            dl->AddRectFilled(ImVec2(at.x - pad, at.y - pad / 2), ImVec2(at.x + ts.x + pad, at.y + ts.y + pad / 2),
                              IM_COL32(10, 12, 16, 200), 3 * ui.scale);
            dl->AddText(at, ImGui::GetColorU32(ed.editsSincePlay() > 0 ? kGold : kDim), note.c_str());
        }
        if (auto rect = ed.selectionRect()) {
            const ImVec2 a(o.x + float(rect->first.x), o.y + float(rect->first.y));
            const ImVec2 b(o.x + float(rect->second.x), o.y + float(rect->second.y));
            dl->AddRectFilled(a, b, IM_COL32(90, 160, 240, 40));
            dl->AddRect(a, b, IM_COL32(90, 160, 240, 200));
        }
        if (!ed.springStart().isNull())
            if (const Position* p = ed.doc.scene.registry.tryGet<Position>(ed.springStart())) {
                const Vec2 a = ed.view.toPixels(p->value), b = ed.mouseViewport();
                dl->AddLine(ImVec2(o.x + float(a.x), o.y + float(a.y)), ImVec2(o.x + float(b.x), o.y + float(b.y)),
                            ImGui::GetColorU32(kGold), 1.5f * ui.scale);
            }
        // The mouse spring: a line from the pulled body to the cursor and a
        // dot where it pulls, so the pull and its direction are seen.
        if (ed.sim.mouseSpring)
            if (const Position* p = ed.doc.scene.registry.tryGet<Position>(ed.sim.mouseSpring->first)) {
                const Vec2 a = ed.view.toPixels(p->value), b = ed.view.toPixels(ed.sim.mouseSpring->second);
                const ImVec2 from(o.x + float(a.x), o.y + float(a.y)), to(o.x + float(b.x), o.y + float(b.y));
                dl->AddLine(from, to, ImGui::GetColorU32(kGold), 2.0f * ui.scale);
                dl->AddCircleFilled(to, 3.5f * ui.scale, ImGui::GetColorU32(kGold));
            }
        // Cursor readout, bottom right of the viewport.
        const Vec2 w = ed.view.toWorld(ed.mouseViewport());
        char text[96];
        std::snprintf(text, sizeof text, "%s  x %.3f  y %.3f m%s", std::string(editor::toolName(ed.tool)).c_str(), w.x, w.y,
                      ed.snap ? "  [snap]" : "");
        const ImVec2 ts = ImGui::CalcTextSize(text);
        dl->AddText(ImVec2(o.x + avail.x - ts.x - 8 * ui.scale, o.y + avail.y - ts.y - 6 * ui.scale),
                    ImGui::GetColorU32(kDim), text);
        if (!ed.sim.message().empty() && ed.sim.running()) {
            const ImVec4 col = ed.sim.diverged() ? kRed : kGold;
            dl->AddText(ImVec2(o.x + 10 * ui.scale, o.y + avail.y - ts.y - 6 * ui.scale), ImGui::GetColorU32(col),
                        ed.sim.message().c_str());
        }
    }
    ImGui::End();
}

} // namespace stepwise::ui
