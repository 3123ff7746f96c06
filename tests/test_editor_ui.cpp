// The editor's ImGui panels with no GL context (ImGui builds its draw lists
// on the CPU, so what a panel draws can be checked directly), and a whole
// editor frame through OSMesa.

#include "render/offscreen.hpp"
#include "ui/editor_ui.hpp"
#include "ui/session.hpp"

#include "stepwise/components.hpp"

#include <GL/osmesa.h>

#include <imgui.h>
#include <imgui_internal.h>

#include <gtest/gtest.h>

namespace {

using stepwise::ui::applyTheme;
using stepwise::ui::beginPanel;

/// An ImGui context with the editor's theme and a built font atlas.
class PanelFrames : public ::testing::Test {
protected:
    void SetUp() override {
        context_ = ImGui::CreateContext();
        applyTheme(1.0f);
        unsigned char* pixels = nullptr;
        int w = 0, h = 0;
        ImGui::GetIO().Fonts->GetTexDataAsAlpha8(&pixels, &w, &h);
        ImGui::GetIO().IniFilename = nullptr;
    }
    void TearDown() override { ImGui::DestroyContext(context_); }

    /// One frame with panel A at (0, 0) and panel B at `b`, both 200 x 200.
    void frame(ImVec2 b) {
        ImGuiIO& io = ImGui::GetIO();
        io.DisplaySize = {800, 600};
        io.DeltaTime = 1.0f / 60.0f;
        ImGui::NewFrame();
        bool open = true;
        ImGui::SetNextWindowPos({0, 0});
        ImGui::SetNextWindowSize({200, 200});
        beginPanel("A", &open);
        ImGui::TextUnformatted("a");
        ImGui::End();
        ImGui::SetNextWindowPos(b);
        ImGui::SetNextWindowSize({200, 200});
        beginPanel("B", &open);
        ImGui::TextUnformatted("b");
        ImGui::End();
        ImGui::Render();
    }

    /// Vertices of the panel's draw list in the panel background colour.
    static int backgroundVertices(const char* name) {
        const ImGuiWindow* w = ImGui::FindWindowByName(name);
        if (!w) return -1;
        const ImU32 background = ImGui::GetColorU32(ImGuiCol_WindowBg);
        int n = 0;
        for (const ImDrawVert& v : w->DrawList->VtxBuffer) n += v.col == background ? 1 : 0;
        return n;
    }

private:
    ImGuiContext* context_ = nullptr;
};

TEST_F(PanelFrames, APanelAloneLeavesItsBackgroundToTheClear) {
    frame({400, 0});  // first frame: nothing known about the other windows yet
    EXPECT_GT(backgroundVertices("A"), 0);
    frame({400, 0});
    EXPECT_EQ(backgroundVertices("A"), 0);
    EXPECT_EQ(backgroundVertices("B"), 0);
}

TEST_F(PanelFrames, OverlappingPanelsDrawTheirBackgrounds) {
    frame({400, 0});
    frame({400, 0});
    frame({100, 100});  // B placed over A
    frame({100, 100});
    EXPECT_GT(backgroundVertices("A"), 0);
    EXPECT_GT(backgroundVertices("B"), 0);
    frame({400, 0});  // apart again
    frame({400, 0});
    EXPECT_EQ(backgroundVertices("A"), 0);
    EXPECT_EQ(backgroundVertices("B"), 0);
}

TEST(SessionFrame, PresentsThePreviousFrameAfterPhysicsAndBeforeDrawing) {
    // The window's swap of frame N runs inside frame N+1, after its physics
    // and before its first GL call, so llvmpipe finishes drawing N while
    // N+1's CPU work runs. The buffer must still hold frame N there.
    const int w = 640, h = 400;
    auto context = stepwise::render::OffscreenRenderer::create(w, h);
    ASSERT_TRUE(context.ok()) << context.error();
    stepwise::ui::SessionOptions options;
    options.persist = false;
    options.deterministic = true;
    options.builtinFont = true;
    auto created = stepwise::ui::Session::create(
        [](const char* name) { return reinterpret_cast<void*>(OSMesaGetProcAddress(name)); }, options);
    ASSERT_TRUE(created.ok()) << created.error();
    stepwise::ui::Session& session = **created;
    stepwise::editor::Editor& ed = session.editor();
    stepwise::Scene scene;
    const stepwise::Entity ball = scene.registry.create();
    scene.registry.emplace<stepwise::Position>(ball, {{0.0, 5.0}});
    scene.registry.emplace<stepwise::Velocity>(ball, {{3.0, 0.0}});
    scene.registry.emplace<stepwise::Mass>(ball, {1.0});
    scene.registry.emplace<stepwise::Radius>(ball, {0.5});
    ed.doc.reset(std::move(scene));
    session.frame(w, h, 1.0 / 60.0);  // lays out the panels and frames the view
    ed.togglePlay();
    session.frame(w, h, 1.0 / 60.0);
    const stepwise::render::Image shown = session.capture(w, h);
    const std::uint64_t stepsBefore = ed.sim.steps();

    int presents = 0;
    std::uint64_t stepsAtPresent = 0;
    stepwise::render::Image atPresent;
    session.frame(w, h, 1.0 / 60.0, [&] {
        ++presents;
        stepsAtPresent = ed.sim.steps();
        atPresent = session.capture(w, h);
    });
    EXPECT_EQ(presents, 1);
    EXPECT_GT(stepsAtPresent, stepsBefore);       // this frame's physics ran first
    EXPECT_EQ(stepsAtPresent, ed.sim.steps());    // and nothing stepped after
    EXPECT_TRUE(atPresent.rgb == shown.rgb);      // the previous frame, untouched
    EXPECT_FALSE(session.capture(w, h).rgb == shown.rgb);  // then this frame was drawn
}

} // namespace
