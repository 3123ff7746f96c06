// Editor scripts (editor/app/script): parsing and line-numbered errors.

#include "editor_fixture.hpp"

using namespace stepwise;
using namespace stepwise::editor;
using namespace stepwise::editor_test;
using stepwise::test::readFile;

TEST(Script, ParsesEveryCommandAndRejectsBadLinesWithTheLineNumber) {
    const char* text = R"(# demo
key Space
key Ctrl+Shift+Z
click 100 200
click world 1.5 -2 right
drag world 0 0 3 4 12
wheel 2 400 300
text "mass 3"
wait 10
step 5
tool circle
overlay velocity on
saveas /tmp/x.json
)";
    Result<std::vector<ScriptCommand>> s = parseScript(text, "demo.txt");
    ASSERT_TRUE(s) << s.error();
    ASSERT_EQ(s->size(), 12u);
    EXPECT_EQ((*s)[1].key, Key::Z);
    EXPECT_EQ((*s)[1].mods, kModCtrl | kModShift);
    EXPECT_TRUE((*s)[3].a.world);
    EXPECT_EQ((*s)[3].button, MouseButton::Right);
    EXPECT_EQ((*s)[4].count, 12);
    EXPECT_EQ((*s)[6].text, "mass 3");
    EXPECT_EQ((*s)[8].count, 5);
    Result<std::vector<ScriptCommand>> bad = parseScript("wait 1\nclick 10\n", "b.txt");
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().find("b.txt:2:"), std::string::npos) << bad.error();
    Result<std::vector<ScriptCommand>> badKey = parseScript("key Hyper+Q\n", "c.txt");
    ASSERT_FALSE(badKey);
    EXPECT_NE(badKey.error().find("Hyper"), std::string::npos);
}

// ---- one table of script actions --------------------------------------------

// The usage line listed eight of the ten tools (no joint, no polygon).
TEST(ScriptActions, UsageAndUnknownToolListEveryTool) {
    Result<std::vector<ScriptCommand>> bare = parseScript("tool\n", "u.txt");
    ASSERT_FALSE(bare);
    EXPECT_EQ(bare.error(), "u.txt:1: expected: tool select|rotate|circle|box|plane|spring|attractor|boids|joint|polygon");
    Editor ed;
    RecordingHost host;
    EXPECT_FALSE(runLine(ed, host, "tool wall"));
    ASSERT_EQ(host.errors.size(), 1u);
    EXPECT_EQ(host.errors[0], "t.txt:1: tool: unknown tool \"wall\" (select, rotate, circle, box, plane, spring, "
                              "attractor, boids, joint, polygon)");
}

TEST(ScriptActions, TheParserChecksArgumentsAgainstTheTable) {
    for (const ScriptAction& a : scriptActions()) {
        EXPECT_EQ(findScriptAction(a.name), &a);
        // One argument too many is refused with the action's usage.
        std::string line = a.name;
        for (std::size_t i = 0; i <= a.maxArgs && a.maxArgs < 1000; ++i) line += " x";
        if (a.maxArgs >= 1000) continue;
        Result<std::vector<ScriptCommand>> r = parseScript(line + "\n", "a.txt");
        ASSERT_FALSE(r) << line;
        EXPECT_EQ(r.error(), "a.txt:1: expected: " + a.usage) << line;
    }
    EXPECT_EQ(findScriptAction("teleport"), nullptr);
    Result<std::vector<ScriptCommand>> steps = parseScript("step 0\n", "s.txt");
    ASSERT_FALSE(steps);
    EXPECT_EQ(steps.error(), "s.txt:1: N must be 1..100000");
}

TEST(ScriptActions, PanelsTabsAndShotsGoToTheHostAndAFailureStopsWithTheLine) {
    Editor ed;
    RecordingHost host;
    EXPECT_TRUE(runLine(ed, host, "window debug off"));
    EXPECT_TRUE(runLine(ed, host, "tab plots"));
    const int framesBefore = host.frames;
    EXPECT_TRUE(runLine(ed, host, "screenshot /tmp/shot.png"));
    EXPECT_EQ(host.frames, framesBefore + 1) << "a screenshot draws its own frame, then none after it";
    EXPECT_EQ(host.calls, (std::vector<std::string>{"window debug off", "tab plots", "screenshot /tmp/shot.png"}));
    EXPECT_FALSE(runLine(ed, host, "window sidebar on"));
    EXPECT_FALSE(runLine(ed, host, "select nobody"));
    EXPECT_EQ(host.errors, (std::vector<std::string>{
                               "t.txt:1: window: expected inspector|world|tools|entities|debug|help on|off",
                               "t.txt:1: select: no entity named \"nobody\""}));
}
