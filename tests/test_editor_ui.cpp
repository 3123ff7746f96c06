// The editor's ImGui panels with no GL context (ImGui builds its draw lists
// on the CPU, so what a panel draws can be checked directly), and a whole
// editor frame through OSMesa.

#include "offscreen.hpp"
#include "ui/editor_ui.hpp"
#include "ui/session.hpp"

#include "stepwise/components.hpp"

#include <GL/osmesa.h>

#include <imgui.h>
#include <imgui_internal.h>

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <memory>

namespace {

/// An editor session on the current offscreen context, as the tests want it:
/// no settings read or written, a fixed clock, the built-in font.
auto headlessSession() {
    stepwise::ui::SessionOptions options;
    options.persist = false;
    options.deterministic = true;
    options.builtinFont = true;
    return stepwise::ui::Session::create(
        [](const char* name) { return reinterpret_cast<void*>(OSMesaGetProcAddress(name)); }, options);
}

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

TEST_F(PanelFrames, TypographicQuotesTheFontLacksAreShownAsAscii) {
    // ImGui's built-in font has no U+201C: the error modal showed '?'.
    ImGui::GetIO().DisplaySize = {800, 600};
    ImGui::NewFrame();
    EXPECT_EQ(stepwise::ui::displayableText("typographic quote \xE2\x80\x9C where JSON needs \"; \xE2\x80\x98" "a\xE2\x80\x99"),
              "typographic quote \" where JSON needs \"; 'a'");
    ImGui::EndFrame();
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
    auto created = headlessSession();
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

// ---- layout across window sizes and restarts --------------------------------------

std::unique_ptr<stepwise::ui::Session> persistentSession(const std::filesystem::path& configDir) {
    stepwise::ui::SessionOptions options;
    options.persist = true;
    options.deterministic = true;
    options.builtinFont = true;
    options.configDir = configDir;
    auto created = stepwise::ui::Session::create(
        [](const char* name) { return reinterpret_cast<void*>(OSMesaGetProcAddress(name)); }, options);
    EXPECT_TRUE(created.ok()) << created.error();
    return created.ok() ? std::move(*created) : nullptr;
}

const char* const kPanels[] = {"Tools", "Entities", "Viewport", "Inspector", "World", "Debug"};

/// "" when every panel lies inside the w x h window, else which one does not.
std::string panelOffScreen(int w, int h) {
    for (const char* name : kPanels) {
        const ImGuiWindow* win = ImGui::FindWindowByName(name);
        if (!win) return std::string(name) + " missing";
        const ImRect r = win->Rect();
        if (r.Min.x < -0.5f || r.Min.y < -0.5f || r.Max.x > float(w) + 0.5f || r.Max.y > float(h) + 0.5f)
            return std::string(name) + " at (" + std::to_string(r.Min.x) + ", " + std::to_string(r.Min.y) + ") - (" +
                   std::to_string(r.Max.x) + ", " + std::to_string(r.Max.y) + ") in " + std::to_string(w) + "x" +
                   std::to_string(h);
    }
    return {};
}

ImRect panelRect(const char* name) { return ImGui::FindWindowByName(name)->Rect(); }

TEST(Layout, ShrinkingToTinyAndBackRestoresThePanelsAndIsNotSaved) {
    const std::filesystem::path config = std::filesystem::temp_directory_path() / ("stepwise-layout-tiny-" + std::to_string(::getpid()));
    std::filesystem::remove_all(config);
    auto context = stepwise::render::OffscreenRenderer::create(1280, 800);
    ASSERT_TRUE(context.ok()) << context.error();
    ImRect inspectorBefore, viewportBefore;
    {
        auto session = persistentSession(config);
        ASSERT_TRUE(session);
        for (int i = 0; i < 3; ++i) session->frame(1280, 800, 1.0 / 60.0);
        inspectorBefore = panelRect("Inspector");
        viewportBefore = panelRect("Viewport");
        for (int i = 0; i < 5; ++i) session->frame(40, 30, 1.0 / 60.0);  // ImGui piles every panel at the top left
        session->saveSettings();  // quitting while tiny must not save the pile
        for (int i = 0; i < 3; ++i) session->frame(1280, 800, 1.0 / 60.0);
        EXPECT_EQ(panelOffScreen(1280, 800), "");
        EXPECT_NEAR(panelRect("Inspector").Min.x, inspectorBefore.Min.x, 1.0f);
        EXPECT_NEAR(panelRect("Inspector").Min.y, inspectorBefore.Min.y, 1.0f);
        EXPECT_NEAR(panelRect("Viewport").GetWidth(), viewportBefore.GetWidth(), 1.0f);
    }
    {
        // Restarted after the save made while tiny: the good layout comes back.
        auto session = persistentSession(config);
        ASSERT_TRUE(session);
        for (int i = 0; i < 3; ++i) session->frame(1280, 800, 1.0 / 60.0);
        EXPECT_EQ(panelOffScreen(1280, 800), "");
        EXPECT_NEAR(panelRect("Inspector").Min.x, inspectorBefore.Min.x, 1.0f);
        EXPECT_NEAR(panelRect("Viewport").GetWidth(), viewportBefore.GetWidth(), 1.0f);
    }
    std::filesystem::remove_all(config);
}

TEST(Layout, ALayoutSavedAt1600x900OpensOnScreenAt1280x720AndResetRestoresTheDefault) {
    const std::filesystem::path config = std::filesystem::temp_directory_path() / ("stepwise-layout-sizes-" + std::to_string(::getpid()));
    std::filesystem::remove_all(config);
    auto context = stepwise::render::OffscreenRenderer::create(1600, 900);
    ASSERT_TRUE(context.ok()) << context.error();
    {
        auto session = persistentSession(config);
        ASSERT_TRUE(session);
        for (int i = 0; i < 3; ++i) session->frame(1600, 900, 1.0 / 60.0);
        EXPECT_EQ(panelOffScreen(1600, 900), "");
        session->saveSettings();
    }
    auto session = persistentSession(config);
    ASSERT_TRUE(session);
    for (int i = 0; i < 3; ++i) session->frame(1280, 720, 1.0 / 60.0);
    EXPECT_EQ(panelOffScreen(1280, 720), "");
    // Move a panel, then View > Reset layout: back to the default rectangles.
    ImGui::SetWindowPos("Inspector", ImVec2(20, 30));
    session->frame(1280, 720, 1.0 / 60.0);
    ASSERT_NEAR(panelRect("Inspector").Min.x, 20.0f, 1.0f);
    session->ui().resetLayoutRequested = true;
    session->frame(1280, 720, 1.0 / 60.0);
    const stepwise::ui::PanelRects defaults = stepwise::ui::defaultLayout(1280, 720, session->ui().scale);
    EXPECT_NEAR(panelRect("Inspector").Min.x, defaults.inspectorPos.x, 0.5f);
    EXPECT_NEAR(panelRect("Inspector").Min.y, defaults.inspectorPos.y, 0.5f);
    EXPECT_NEAR(panelRect("Viewport").GetWidth(), defaults.viewportSize.x, 0.5f);
    EXPECT_NEAR(panelRect("Debug").Min.y, defaults.debugPos.y, 0.5f);
    session.reset();
    std::filesystem::remove_all(config);
}

} // namespace

// ---- the mouse spring is drawn ----------------------------------------------------

// While playing, a drag on a body pulls it with a spring to the cursor; the
// viewport drew nothing of it.
TEST(SessionFrame, TheMouseSpringDrawsALineFromTheBodyToTheCursor) {
    const int w = 800, h = 600;
    auto context = stepwise::render::OffscreenRenderer::create(w, h);
    ASSERT_TRUE(context.ok()) << context.error();
    auto created = headlessSession();
    ASSERT_TRUE(created.ok()) << created.error();
    stepwise::ui::Session& session = **created;
    stepwise::editor::Editor& ed = session.editor();
    stepwise::Scene scene;
    scene.world.gravity = {0.0, 0.0};
    const stepwise::Entity ball = scene.registry.create();
    scene.registry.emplace<stepwise::Position>(ball, {{0.0, 0.0}});
    scene.registry.emplace<stepwise::Mass>(ball, {1.0});
    scene.registry.emplace<stepwise::Radius>(ball, {0.2});
    const stepwise::Entity far = scene.registry.create();  // frames a view 10 m wide
    scene.registry.emplace<stepwise::Position>(far, {{10.0, 0.0}});
    scene.registry.emplace<stepwise::Static>(far, {});
    scene.registry.emplace<stepwise::Radius>(far, {0.2});
    ed.doc.reset(std::move(scene));
    using stepwise::editor::InputEvent;
    auto event = [](InputEvent::Type t, float x, float y) {
        InputEvent e;
        e.type = t;
        e.x = x;
        e.y = y;
        return e;
    };
    session.frame(w, h, 1.0 / 60.0);
    ed.fitView();
    ed.togglePlay();
    session.frame(w, h, 1.0 / 60.0);
    const ImVec2 o = session.viewportPos();
    const stepwise::Vec2 at = ed.view.toPixels({0.0, 0.0});
    const float bx = o.x + float(at.x), by = o.y + float(at.y);
    const float cursorX = bx + 160.0f;
    session.queue(event(InputEvent::Type::MouseMove, bx, by));
    session.frame(w, h, 1.0 / 60.0);
    session.queue(event(InputEvent::Type::MouseDown, bx, by));
    session.frame(w, h, 1.0 / 60.0);
    session.queue(event(InputEvent::Type::MouseMove, cursorX, by));
    session.frame(w, h, 1.0 / 60.0);
    session.frame(w, h, 1.0 / 60.0);  // panels are built before a frame's events are routed
    ASSERT_TRUE(ed.sim.mouseSpring.has_value()) << "the press did not grab the ball";
    // The pixel halfway between the ball (where it is now) and the cursor.
    const stepwise::Vec2 now = ed.view.toPixels(ed.doc.scene.registry.tryGet<stepwise::Position>(ball)->value);
    const int midX = int(std::lround((o.x + float(now.x) + cursorX) / 2)), midY = int(std::lround(by));
    const stepwise::render::Image image = session.capture(w, h);
    // The line's colour (the editor's gold, 255 209 102) within 40 per channel,
    // anywhere in the 5 rows around the line's row.
    bool gold = false;
    for (int y = midY - 2; y <= midY + 2; ++y) {
        const std::uint8_t* p = image.pixel(midX, y);
        gold = gold || (std::abs(p[0] - 255) <= 40 && std::abs(p[1] - 209) <= 40 && std::abs(p[2] - 102) <= 40);
    }
    EXPECT_TRUE(gold) << "no line at (" << midX << ", " << midY << ")";
    session.queue(event(InputEvent::Type::MouseUp, cursorX, by));
    session.frame(w, h, 1.0 / 60.0);
    EXPECT_FALSE(ed.sim.mouseSpring.has_value());
}

// ---- a failed open from the recent list -----------------------------------------

// File > Open recent on a level deleted since: the Error modal with the
// loader's reason, and the status line with it (it said "open failed: PATH").
TEST(SessionFrame, OpenRecentOnADeletedLevelShowsTheReasonInTheModalAndTheStatusLine) {
    const int w = 1280, h = 720;
    auto context = stepwise::render::OffscreenRenderer::create(w, h);
    ASSERT_TRUE(context.ok()) << context.error();
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("stepwise-recent-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::filesystem::path gone = dir / "gone.json";
    std::filesystem::copy_file(std::filesystem::path(STEPWISE_SOURCE_DIR) / "levels" / "default.json", gone,
                               std::filesystem::copy_options::overwrite_existing);
    auto created = headlessSession();
    ASSERT_TRUE(created.ok()) << created.error();
    stepwise::ui::Session& session = **created;
    stepwise::editor::Editor& ed = session.editor();
    ASSERT_TRUE(session.openAtStart(gone));
    ASSERT_TRUE(ed.open(std::filesystem::path(STEPWISE_SOURCE_DIR) / "levels" / "orbit.json"));
    std::filesystem::remove(gone);
    using stepwise::editor::InputEvent;
    auto click = [&](float x, float y) {
        for (const InputEvent::Type t : {InputEvent::Type::MouseMove, InputEvent::Type::MouseDown, InputEvent::Type::MouseUp}) {
            InputEvent e;
            e.type = t;
            e.x = x;
            e.y = y;
            session.queue(e);
            session.frame(w, h, 1.0 / 60.0);
        }
    };
    auto hover = [&](float x, float y) {
        InputEvent e;
        e.type = InputEvent::Type::MouseMove;
        e.x = x;
        e.y = y;
        session.queue(e);
        session.frame(w, h, 1.0 / 60.0);
        session.frame(w, h, 1.0 / 60.0);
    };
    /// The middle of row `row` of a menu window.
    auto rowOf = [](const char* menu, int row) {
        const ImGuiWindow* win = ImGui::FindWindowByName(menu);
        EXPECT_NE(win, nullptr) << menu;
        if (!win) return ImVec2(0, 0);
        const ImGuiStyle& style = ImGui::GetStyle();
        const float rowHeight = ImGui::GetFontSize() + style.ItemSpacing.y;
        return ImVec2(win->Pos.x + 30.0f, win->Pos.y + style.WindowPadding.y + rowHeight * (float(row) + 0.5f) - style.ItemSpacing.y / 2);
    };
    session.frame(w, h, 1.0 / 60.0);
    click(20.0f, 10.0f);  // File
    const ImVec2 recent = rowOf("##Menu_00", 2);  // New, Open..., Open recent
    hover(recent.x, recent.y);
    const ImVec2 first = rowOf("##Menu_01", 0);  // the newest recent file: orbit.json, then gone.json
    const ImVec2 second(first.x, first.y + ImGui::GetFontSize() + ImGui::GetStyle().ItemSpacing.y);
    hover(second.x, recent.y);  // along the row first, so the submenu stays open
    click(second.x, second.y);
    session.frame(w, h, 1.0 / 60.0);
    const std::string loader = gone.string() + ": error: no such file";
    EXPECT_EQ(ed.errorModal, loader);
    EXPECT_EQ(ed.status, "open failed: " + loader);
    EXPECT_EQ(session.dialogState().modal, "Error");
    EXPECT_EQ(ed.doc.title(), "orbit.json");
    std::filesystem::remove_all(dir);
}

// ---- where the save dialogs propose to write ---------------------------------------

// "Save simulation state" kept the path last typed into Save as, for another
// level; Save as on a new level proposed the program's own levels folder.
TEST(SessionFrame, EachSaveDialogProposesAPathFromTheLevelOpenNow) {
    const int w = 1280, h = 720;
    auto context = stepwise::render::OffscreenRenderer::create(w, h);
    ASSERT_TRUE(context.ok()) << context.error();
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("stepwise-proposals-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir / "mine");
    const std::filesystem::path bridge = dir / "mine" / "bridge.json";
    std::filesystem::copy_file(std::filesystem::path(STEPWISE_SOURCE_DIR) / "levels" / "bridge.json", bridge);
    auto created = headlessSession();
    ASSERT_TRUE(created.ok()) << created.error();
    stepwise::ui::Session& session = **created;
    stepwise::editor::Editor& ed = session.editor();
    stepwise::ui::UiState& ui = session.ui();
    ASSERT_TRUE(session.openAtStart(bridge));
    session.frame(w, h, 1.0 / 60.0);
    ui.saveAsPath = (dir / "elsewhere" / "other.json").string();  // typed for another level, earlier
    ed.stepForward();
    ui.saveStateRequested = true;
    session.frame(w, h, 1.0 / 60.0);
    EXPECT_EQ(session.dialogState().modal, "Save simulation state");
    EXPECT_EQ(ui.saveAsPath, (dir / "mine" / "bridge_state.json").string());
    ImGui::ClosePopupToLevel(0, false);
    ed.resetSimulation();
    // A new level: the working folder.
    const std::filesystem::path before = std::filesystem::current_path();
    std::filesystem::current_path(dir);
    ed.newDocument();
    ui.saveAsDialogRequested = true;
    session.frame(w, h, 1.0 / 60.0);
    std::filesystem::current_path(before);
    EXPECT_EQ(session.dialogState().modal, "Save as");
    EXPECT_EQ(ui.saveAsPath, (dir / "untitled.json").string());
    std::filesystem::remove_all(dir);
}

// ---- the legend leaves the scene to the scene -------------------------------------

// With every overlay on, the legend was one row per overlay, a column that
// took 44% of the viewport's height at 1280x720 and hid half of a pyramid.
// Its cells now share rows, at every common window size, in the editor's own
// viewport (the render command draws the same legend: ViewportMatchesRender).
TEST(SessionFrame, WithEveryOverlayOnTheLegendTakesASmallShareOfTheViewport) {
    struct Size {
        int w, h;
        double most;  // of the viewport's height
    };
    for (const char* level : {"car.json", "pyramid.json"})
        for (const Size size : {Size{800, 600, 0.20}, Size{1280, 720, 0.15}, Size{1600, 900, 0.15}, Size{1920, 1080, 0.15}}) {
            auto context = stepwise::render::OffscreenRenderer::create(size.w, size.h);
            ASSERT_TRUE(context.ok()) << context.error();
            auto created = headlessSession();
            ASSERT_TRUE(created.ok()) << created.error();
            stepwise::ui::Session& session = **created;
            stepwise::editor::Editor& ed = session.editor();
            ASSERT_TRUE(ed.open(std::filesystem::path(STEPWISE_SOURCE_DIR) / "levels" / level));
            for (const auto& [name, overlay] : stepwise::render::overlayNames()) ed.overlays.add(overlay);
            session.frame(size.w, size.h, 1.0 / 60.0);
            ed.fitView();
            ed.togglePlay();
            for (int i = 0; i < 30; ++i) session.frame(size.w, size.h, 1.0 / 60.0);
            const std::string at = std::string(level) + " at " + std::to_string(size.w) + "x" + std::to_string(size.h);
            const stepwise::ui::UiState::FrameParts& frame = session.ui().lastFrame;
            const auto [x, y, w, h] = frame.legendBox;
            const ImVec2 viewport = session.viewportSize();
            // Every arrow overlay's reference is there (the pyramid has no joints).
            EXPECT_GE(frame.legendRows, std::string(level) == "car.json" ? 7u : 6u) << at;
            EXPECT_GT(h, 0.0) << at;
            EXPECT_GE(x, 0.0) << at;
            EXPECT_GE(y, 0.0) << at;
            EXPECT_LE(x + w, viewport.x) << at;
            EXPECT_LE(y + h, viewport.y) << at;
            const double fraction = h / viewport.y;
            EXPECT_LT(fraction, size.most) << at << ": the legend is " << h << " of " << viewport.y << " px high";
            std::printf("legend %s: %.0f x %.0f px in %.0f x %.0f, %.1f%% of the height\n", at.c_str(), w, h, viewport.x,
                        viewport.y, 100.0 * fraction);
        }
}

// ---- the Tools panel at common window sizes -----------------------------------

// At 1280x720 the Tools panel scrolled to reach its last overlay boxes, and
// with the Joint tool its hint and half the overlays were below the fold.
// Every tool's panel now shows every control whole, with nothing to scroll.
TEST(Layout, TheToolsPanelShowsEveryControlWholeWithoutScrolling) {
    for (const auto& [w, h] : {std::pair{1280, 720}, std::pair{1600, 900}, std::pair{1024, 768}}) {
        auto context = stepwise::render::OffscreenRenderer::create(w, h);
        ASSERT_TRUE(context.ok()) << context.error();
        auto created = headlessSession();
        ASSERT_TRUE(created.ok()) << created.error();
        stepwise::ui::Session& session = **created;
        stepwise::editor::Editor& ed = session.editor();
        ASSERT_TRUE(ed.open(std::filesystem::path(STEPWISE_SOURCE_DIR) / "levels" / "default.json"));
        for (int t = 0; t < int(stepwise::editor::Tool::Count); ++t) {
            ed.tool = stepwise::editor::Tool(t);
            session.ui().widgetRects.clear();
            for (int i = 0; i < 3; ++i) session.frame(w, h, 1.0 / 60.0);
            const std::string at = std::string(stepwise::editor::toolName(ed.tool)) + " tool at " + std::to_string(w) +
                                   "x" + std::to_string(h);
            const ImGuiWindow* tools = ImGui::FindWindowByName("Tools");
            ASSERT_NE(tools, nullptr);
            EXPECT_EQ(tools->ScrollMax.y, 0.0f) << at << ": " << tools->ScrollMax.y << " px to scroll";
            // Every control (its label too) inside the panel's visible inside.
            const ImRect inside = tools->InnerClipRect;
            int controls = 0, buttons = 0;
            for (const auto& [key, r] : session.ui().widgetRects) {
                if (key.rfind("tools/", 0) != 0) continue;
                ++controls;
                EXPECT_GE(r.x, inside.Min.x - 0.5f) << at << ": " << key;
                EXPECT_GE(r.y, inside.Min.y - 0.5f) << at << ": " << key;
                EXPECT_LE(r.x + r.z, inside.Max.x + 0.5f) << at << ": " << key << " is cut at the right";
                EXPECT_LE(r.y + r.w, inside.Max.y + 0.5f) << at << ": " << key << " is below the fold";
                if (key.rfind("tools/tool/", 0) == 0) {
                    // A tool button's label ("7  Attractor") fits between its frame's paddings.
                    ++buttons;
                    const stepwise::editor::Tool tool = *stepwise::editor::toolFromScriptName(key.substr(11));
                    const std::string label = std::string(stepwise::editor::keyName(stepwise::editor::toolKey(tool))) +
                                              "  " + std::string(stepwise::editor::toolName(tool));
                    EXPECT_LE(ImGui::CalcTextSize(label.c_str()).x + 2 * ImGui::GetStyle().FramePadding.x, r.z + 0.5f)
                        << at << ": " << label << " is cut";
                }
            }
            EXPECT_EQ(buttons, int(stepwise::editor::Tool::Count)) << at;
            // The tool buttons, snap, the overlay boxes, and the tool's own options.
            EXPECT_GE(controls, int(stepwise::editor::Tool::Count) + 1 + 9) << at;
        }
    }
}
