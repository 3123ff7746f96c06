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
