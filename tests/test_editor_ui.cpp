// The editor's ImGui panels with no GL context: ImGui builds its draw lists
// on the CPU, so what a panel draws can be checked directly.

#include "ui/editor_ui.hpp"

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

} // namespace
