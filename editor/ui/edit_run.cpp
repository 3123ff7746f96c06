#include "ui/edit_run.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"

#include <imgui_internal.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <numeric>
#include <sstream>

namespace stepwise::ui {

void writeDebugState(const std::string& path, ui::Session& session, std::uint64_t frame) {
    editor::Editor& ed = session.editor();
    std::ostringstream out;
    out.precision(17);
    const char* mode = ed.sim.state() == editor::SimState::Playing ? "playing"
                       : ed.sim.state() == editor::SimState::Paused ? "paused" : "editing";
    const ImVec2 p = session.viewportPos(), z = session.viewportSize();
    out << "{\n  \"frame\": " << frame << ",\n  \"mode\": \"" << mode << "\",\n  \"time\": " << ed.doc.scene.world.time
        << ",\n  \"steps\": " << ed.sim.steps() << ",\n  \"entities\": " << ed.doc.scene.registry.size()
        << ",\n  \"dirty\": " << (ed.dirty() ? "true" : "false") << ",\n  \"viewport\": [" << p.x << ", " << p.y << ", "
        << z.x << ", " << z.y << "],\n  \"camera\": [" << ed.view.camera.center.x << ", " << ed.view.camera.center.y
        << ", " << ed.view.camera.zoom << "],\n  \"selection\": " << ed.selection.size();
    const ui::Session::DialogState d = session.dialogState();
    out << ",\n  \"modal\": " << nlohmann::json(d.modal).dump() << ",\n  \"status\": " << nlohmann::json(d.status).dump()
        << ",\n  \"open_folder\": " << nlohmann::json(d.openFolder).dump() << ",\n  \"open_files\": " << d.openFiles
        << ",\n  \"save_as_suggestion\": " << nlohmann::json(d.saveAsSuggestion).dump()
        << ",\n  \"error\": " << nlohmann::json(ed.errorModal).dump()
        << ",\n  \"window\": [" << ImGui::GetIO().DisplaySize.x << ", " << ImGui::GetIO().DisplaySize.y << "]"
        << ",\n  \"tool\": " << nlohmann::json(std::string(editor::toolName(ed.tool))).dump();
    // Rectangles (x, y, w, h) in window pixels of the panels and of the
    // inspector's fields, from the last frame.
    nlohmann::json windows = nlohmann::json::object(), widgets = nlohmann::json::object();
    for (const char* name : {"Tools", "Entities", "Viewport", "Inspector", "World", "Debug"})
        if (const ImGuiWindow* w = ImGui::FindWindowByName(name); w && w->WasActive)
            windows[name] = {w->Pos.x, w->Pos.y, w->Size.x, w->Size.y};
    for (const auto& [key, r] : session.ui().widgetRects) widgets[key] = {r.x, r.y, r.z, r.w};
    out << ",\n  \"windows\": " << windows.dump() << ",\n  \"widgets\": " << widgets.dump() << ",\n  \"positions\": [";
    int n = 0;
    for (Entity e : ed.doc.scene.registry.entities()) {
        const Position* pos = ed.doc.scene.registry.tryGet<Position>(e);
        if (!pos || ed.doc.scene.registry.has<Spring>(e)) continue;
        out << (n ? ", " : "") << "[" << pos->value.x << ", " << pos->value.y << "]";
        if (++n == 64) break;
    }
    out << "]\n}\n";
    (void)writeFileAtomically(path, out.str());
}

namespace {
double processCpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}
} // namespace

void FrameTimes::add(double frameMs, const ui::UiState::FrameParts& parts) {
    processCpuLast = processCpuSeconds();
    if (processCpuStart < 0.0) processCpuStart = processCpuLast;
    ms.push_back(frameMs);
    sum.uiMs += parts.uiMs;
    sum.stepMs += parts.stepMs;
    sum.sceneMs += parts.sceneMs;
    sum.drawUiMs += parts.drawUiMs;
    sum.presentMs += parts.presentMs;
    sum.steps += parts.steps;
    last = parts;
}

void FrameTimes::report(const char* what, std::size_t bodies) const {
    if (ms.empty()) return;
    std::vector<double> sorted = ms;
    std::sort(sorted.begin(), sorted.end());
    const double n = double(sorted.size());
    const double mean = std::accumulate(sorted.begin(), sorted.end(), 0.0) / n;
    std::printf("edit bench (%s): %zu entities, %zu frames: mean %.2f ms, median %.2f ms, p95 %.2f ms, max %.2f ms "
                "(%.1f fps at the mean)\n",
                what, bodies, sorted.size(), mean, sorted[sorted.size() / 2], sorted[sorted.size() * 95 / 100],
                sorted.back(), 1000.0 / mean);
    // Where a frame goes. "present" is the previous frame's buffer
    // swap (Session::frame): waiting for llvmpipe to finish drawing it,
    // then (under Xvfb) the copy to the X server. The rest is events.
    const double parts = (sum.uiMs + sum.stepMs + sum.sceneMs + sum.drawUiMs + sum.presentMs) / n;
    std::printf("  per frame: ui build %.2f ms, physics %.2f ms (%.2f steps), viewport render %.2f ms, "
                "ui draw %.2f ms, present %.2f ms, rest %.2f ms\n",
                sum.uiMs / n, sum.stepMs / n, double(sum.steps) / n, sum.sceneMs / n, sum.drawUiMs / n,
                sum.presentMs / n, std::max(0.0, mean - parts));
    // Between the first and the last add(): n - 1 frames apart.
    if (sorted.size() > 1)
        std::printf("  CPU time of all the process's threads: %.2f ms a frame\n",
                    1e3 * (processCpuLast - processCpuStart) / (n - 1.0));
    std::printf("  viewport, last frame: %zu instances in %d draw calls\n", last.instances, last.drawCalls);
}

} // namespace stepwise::ui
