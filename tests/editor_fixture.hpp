#pragma once
// What the editor-model tests share (test_editor.cpp, test_scene_edit.cpp,
// test_simulation.cpp, test_document.cpp, ...): an Editor with a level open
// in a temporary config folder, and mouse gestures in world coordinates.

#include "app/editor.hpp"
#include "app/scene_edit.hpp"
#include "app/script.hpp"
#include "app/script_actions.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <vector>
#include <string>

namespace stepwise::editor_test {

using namespace stepwise;
using namespace stepwise::editor;


inline const std::filesystem::path kLevels = std::filesystem::path(STEPWISE_SOURCE_DIR) / "levels";

inline std::string textOf(const Scene& s) { return sceneToJsonText(s); }

using stepwise::test::readFile;

/// A fresh temporary folder per test, removed afterwards.
struct TempDir : stepwise::test::TempDir {
    TempDir() : stepwise::test::TempDir("stepwise-editor-test") {}
};

/// Editor with levels/<level> open, its config in a temporary folder.
struct LevelOpen {
    TempDir tmp;
    Editor ed;
    explicit LevelOpen(const std::string& level) {
        ed.configDir = tmp.path / "config";
        EXPECT_TRUE(ed.open(kLevels / level)) << ed.errorModal;
    }
};

/// The same with a 800x600 viewport framing the level, and mouse gestures.
struct Fixture : LevelOpen {
    explicit Fixture(const std::string& level) : LevelOpen(level) {
        ed.setViewportSize(800, 600);
        ed.fitView();
    }
    InputEvent mouse(InputEvent::Type t, Vec2 world, std::uint8_t mods = 0) const {
        InputEvent e;
        e.type = t;
        const Vec2 px = ed.view.toPixels(world);
        e.x = px.x;
        e.y = px.y;
        e.mods = mods;
        return e;
    }
    void click(Vec2 world, std::uint8_t mods = 0) {
        ed.handleViewportEvent(mouse(InputEvent::Type::MouseDown, world, mods));
        ed.handleViewportEvent(mouse(InputEvent::Type::MouseUp, world, mods));
    }
    void drag(Vec2 from, Vec2 to, int moves) {
        ed.handleViewportEvent(mouse(InputEvent::Type::MouseDown, from));
        for (int i = 1; i <= moves; ++i)
            ed.handleViewportEvent(mouse(InputEvent::Type::MouseMove, from + (to - from) * (double(i) / moves)));
        ed.handleViewportEvent(mouse(InputEvent::Type::MouseUp, to));
    }
    Entity named(const std::string& n) const { return findByName(ed.doc.scene.registry, n); }
    Vec2 positionOf(const std::string& n) const {
        return ed.doc.scene.registry.tryGet<Position>(named(n))->value;
    }
};


/// Renames `e` through the inspector's path (setFieldOnAll on "name"):
/// whether it changed the name, or why it was refused.
inline Result<bool> rename(Fixture& f, Entity e, const std::string& to) {
    const ComponentInfo* name = findComponent("name");
    return f.ed.tryEdit("rename", [&](Scene& s) {
        return changedAny(setFieldOnAll(s, *name, name->fields[0], std::string(to), {e}));
    });
}

// ---- the scripted runner's side, for script-action tests

/// The scripted runner's side, recorded: frames drawn, panels, tabs, shots.
struct RecordingHost final : ScriptHost {
    int frames = 0;
    std::vector<std::string> calls, errors;
    void frame() override { ++frames; }
    bool showWindow(const std::string& name, bool on) override {
        calls.push_back("window " + name + (on ? " on" : " off"));
        return name == "debug";
    }
    bool showDebugTab(const std::string& name) override {
        calls.push_back("tab " + name);
        return name == "plots";
    }
    Result<void> screenshot(const std::string& path) override {
        calls.push_back("screenshot " + path);
        return {};
    }
    void reportError(const std::string& message) override { errors.push_back(message); }
};

/// Parses one script line and runs it as the headless runner does.
inline bool runLine(Editor& ed, RecordingHost& host, const std::string& line) {
    Result<std::vector<ScriptCommand>> parsed = parseScript(line + "\n", "t.txt");
    EXPECT_TRUE(parsed) << parsed.error();
    if (!parsed) return false;
    EXPECT_EQ(parsed->size(), 1u);
    return runScriptAction(ed, host, parsed->front(), "t.txt");
}


} // namespace stepwise::editor_test
