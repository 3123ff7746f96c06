// Files (editor/app/document and the Editor's save paths): atomic saves,
// autosave and recovery, messages for unwritable folders.

#include "editor_fixture.hpp"

#include <chrono>
#include <random>
#include <fstream>

using namespace stepwise;
using namespace stepwise::editor;
using namespace stepwise::editor_test;
using stepwise::test::readFile;

TEST(Files, SaveIsAtomicAndEqualsTheExpectedJson) {
    Fixture f("orbit.json");
    const std::filesystem::path out = f.tmp.path / "out.json";
    ASSERT_TRUE(f.ed.applyEdit("add", [](Scene& s) {
        addCircle(s, {1.0, 2.0}, 0.25);
        return true;
    }));
    Scene expected = f.ed.doc.scene;
    ASSERT_TRUE(f.ed.saveAs(out)) << f.ed.errorModal;
    EXPECT_EQ(readFile(out), sceneToJsonText(expected));
    EXPECT_FALSE(f.ed.dirty());
    // No temporaries left next to it.
    for (const auto& entry : std::filesystem::directory_iterator(f.tmp.path))
        EXPECT_TRUE(entry.path().filename() == "out.json" || entry.path().filename() == "config") << entry.path();
    // While playing, Save writes the edited level, not the state.
    f.ed.togglePlay();
    for (int i = 0; i < 10; ++i) f.ed.update(1.0 / 60.0);
    ASSERT_TRUE(f.ed.handleShortcut(Key::S, kModCtrl));
    EXPECT_EQ(readFile(out), sceneToJsonText(expected));
}

TEST(Files, UnwritableFolderAndBadLevelGiveMessagesNotCrashes) {
    Fixture f("orbit.json");
    const std::string before = textOf(f.ed.doc.scene);
    EXPECT_FALSE(f.ed.saveAs(f.tmp.path / "missing" / "folder" / "x.json"));
    EXPECT_FALSE(f.ed.errorModal.empty());
    f.ed.errorModal.clear();
    const std::filesystem::path bad = f.tmp.path / "bad.json";
    { std::ofstream(bad) << "{\"entities\": [ {\"mass\": -1} ]}"; }
    EXPECT_FALSE(f.ed.open(bad));
    EXPECT_NE(f.ed.errorModal.find("mass"), std::string::npos) << f.ed.errorModal;
    EXPECT_EQ(textOf(f.ed.doc.scene), before);  // the document is untouched
    f.ed.errorModal.clear();
    EXPECT_FALSE(f.ed.open(f.tmp.path / "no-such-level.json"));
    EXPECT_FALSE(f.ed.errorModal.empty());
    // An invalid scene (duplicate names) is refused before writing.
    ASSERT_TRUE(f.ed.applyEdit("dup", [](Scene& s) {
        const Entity e = s.registry.create();
        s.registry.emplace(e, Name{"sun"});
        s.registry.emplace(e, Position{});
        return true;
    }));
    EXPECT_FALSE(f.ed.saveAs(f.tmp.path / "dup.json"));
    EXPECT_FALSE(std::filesystem::exists(f.tmp.path / "dup.json"));
}

TEST(Files, AReadOnlyFolderGivesAMessageForSaveAndAutosave) {
    // /proc takes no new files, even from root (CI runs as root, where a
    // chmod'ed folder would still be writable).
    Fixture f("orbit.json");
    ASSERT_TRUE(f.ed.applyEdit("G", [](Scene& s) {
        s.world.G = 4.0;
        return true;
    }));
    const std::string edited = textOf(f.ed.doc.scene);
    EXPECT_FALSE(f.ed.saveAs("/proc/stepwise-level.json"));
    EXPECT_NE(f.ed.errorModal.find("Cannot save /proc/stepwise-level.json"), std::string::npos) << f.ed.errorModal;
    EXPECT_TRUE(f.ed.dirty());  // nothing was saved, and nothing is lost
    EXPECT_EQ(textOf(f.ed.doc.scene), edited);
    f.ed.configDir = "/proc/stepwise-config";
    EXPECT_FALSE(f.ed.tickAutosave(0.0));
    EXPECT_FALSE(f.ed.tickAutosave(31.0));
    EXPECT_EQ(f.ed.status.rfind("autosave failed: ", 0), 0u) << f.ed.status;
    EXPECT_EQ(textOf(f.ed.doc.scene), edited);
}

TEST(Files, UnsavedChangesAreAskedAbout) {
    Fixture f("orbit.json");
    f.ed.request(PendingAction::New);  // clean: happens at once
    EXPECT_EQ(f.ed.doc.title(), "untitled");
    ASSERT_TRUE(f.ed.open(kLevels / "orbit.json"));
    ASSERT_TRUE(f.ed.applyEdit("G", [](Scene& s) {
        s.world.G = 3.0;
        return true;
    }));
    f.ed.request(PendingAction::Open, kLevels / "spring_chain.json");
    EXPECT_EQ(f.ed.uiRequest, UiRequest::ConfirmDiscard);
    EXPECT_EQ(f.ed.doc.title(), "orbit.json");
    f.ed.resolvePending(Editor::Resolution::Cancel);
    EXPECT_EQ(f.ed.doc.title(), "orbit.json");
    f.ed.request(PendingAction::Open, kLevels / "spring_chain.json");
    f.ed.resolvePending(Editor::Resolution::Discard);
    EXPECT_EQ(f.ed.doc.title(), "spring_chain.json");
}

TEST(Files, AutosaveWritesRecoveryAndRecoverRestoresIt) {
    Fixture f("orbit.json");
    const std::filesystem::path level = f.tmp.path / "level.json";
    std::filesystem::copy_file(kLevels / "orbit.json", level);
    ASSERT_TRUE(f.ed.open(level));
    EXPECT_FALSE(f.ed.tickAutosave(0.0));
    ASSERT_TRUE(f.ed.applyEdit("G", [](Scene& s) {
        s.world.G = 7.0;
        return true;
    }));
    EXPECT_FALSE(f.ed.tickAutosave(10.0));  // not 30 s yet
    EXPECT_TRUE(f.ed.tickAutosave(31.0));
    const std::string edited = textOf(f.ed.doc.scene);
    // A "crash": a new editor on the same level finds the recovery file.
    Editor again;
    again.configDir = f.ed.configDir;
    ASSERT_TRUE(again.open(level));
    const auto recovery = again.recoveryAvailable();
    ASSERT_TRUE(recovery);
    ASSERT_TRUE(again.recover(*recovery));
    EXPECT_EQ(textOf(again.doc.scene), edited);
    EXPECT_TRUE(again.dirty());
    ASSERT_TRUE(again.save());
    EXPECT_FALSE(again.recoveryAvailable());  // saving removes it
}

TEST(Files, SaveAsRemovesTheOldPathsRecoveryCopy) {
    Fixture f("orbit.json");
    const std::filesystem::path a = f.tmp.path / "a.json", b = f.tmp.path / "b.json";
    std::filesystem::copy_file(kLevels / "orbit.json", a);
    ASSERT_TRUE(f.ed.open(a));
    ASSERT_TRUE(f.ed.applyEdit("G", [](Scene& s) {
        s.world.G = 5.0;
        return true;
    }));
    EXPECT_FALSE(f.ed.tickAutosave(0.0));
    ASSERT_TRUE(f.ed.tickAutosave(31.0));
    const std::filesystem::path recoveryOfA = f.ed.doc.recoveryPath(f.ed.configDir);
    ASSERT_TRUE(std::filesystem::exists(recoveryOfA));
    ASSERT_TRUE(f.ed.saveAs(b));
    // The work is in b.json now; a.json's copy would be offered, stale, the
    // next time a.json opens.
    EXPECT_FALSE(std::filesystem::exists(recoveryOfA));
    Editor again;
    again.configDir = f.ed.configDir;
    ASSERT_TRUE(again.open(a));
    EXPECT_FALSE(again.recoveryAvailable());
}

TEST(Files, AutosaveKilledAtRandomPointsLeavesAWholeRecoveryFile) {
    // 120 kills in the release stage. Under AddressSanitizer each kill forks
    // the instrumented process and autosaves 2,000 bodies, so 120 take about
    // 164 s, the longest test in CI by far; 24 kills there still run every
    // path of the save under the sanitizer, and the release stage keeps the
    // 120.
#ifdef STEPWISE_UNDER_ASAN
    constexpr int kKills = 24;
#else
    constexpr int kKills = 120;
#endif
    Fixture f("pile.json");  // ~2,000 bodies: an autosave long enough to be hit mid-write
    const std::filesystem::path level = f.tmp.path / "level.json";
    std::filesystem::copy_file(kLevels / "pile.json", level);
    ASSERT_TRUE(f.ed.open(level));
    const std::filesystem::path recovery = f.ed.doc.recoveryPath(f.ed.configDir);
    // The two versions the child alternates between: G = 2 and G = 3.
    std::string versions[2];
    for (int v = 0; v < 2; ++v) {
        Scene s = f.ed.levelToSave();
        s.world.G = 2.0 + v;
        versions[v] = sceneToJsonText(s);
    }
    ASSERT_NE(versions[0], versions[1]);
    const auto autosave = [&f](int k, double now) {
        f.ed.applyEdit("G", [k](Scene& s) {
            s.world.G = 2.0 + (k % 2);
            return true;
        });
        return f.ed.tickAutosave(now);
    };
    // How long one autosave takes here (sanitizers make it slower): the
    // kills are spread over two of them.
    ASSERT_FALSE(autosave(0, 0.0));  // the first tick starts the 30 s clock
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_TRUE(autosave(1, 31.0));
    const auto micros = std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - t0).count();
    std::filesystem::remove(recovery);

    std::mt19937 rng(20261201u);
    std::uniform_int_distribution<long long> delayMicros(0, 2 * micros);
    for (int kill = 0; kill < kKills; ++kill) {
        // One whole autosave first, then autosave forever (a new version
        // each time) until killed.
        double now = 100.0 + 31.0 * kill;
        int k = kill;
        const std::string killed = stepwise::test::killWhileWorking(
            [&] { return autosave(k, now); }, [&] { return autosave(++k, now += 31.0); },
            std::chrono::microseconds(delayMicros(rng)));
        ASSERT_EQ(killed, "") << "kill " << kill;
        const std::string onDisk = readFile(recovery);
        ASSERT_TRUE(onDisk == versions[0] || onDisk == versions[1])
            << "kill " << kill << ": the recovery file is neither version (" << onDisk.size() << " bytes)";
    }
    // A fresh editor on the level is offered the recovery copy and gets it whole.
    Editor again;
    again.configDir = f.ed.configDir;
    ASSERT_TRUE(again.open(level));
    const auto offered = again.recoveryAvailable();
    ASSERT_TRUE(offered);
    ASSERT_TRUE(again.recover(*offered));
    const double g = again.doc.scene.world.G;
    EXPECT_TRUE(g == 2.0 || g == 3.0) << g;
}

TEST(Files, LevelsFolderIsFoundFromTheExecutableNotTheWorkingFolder) {
    TempDir elsewhere;
    // A build folder in a checkout: <src>/build/stepwise -> <src>/levels.
    const std::filesystem::path levels = findLevelsDirectory(std::filesystem::path(STEPWISE_BINARY).parent_path(), elsewhere.path);
    EXPECT_TRUE(std::filesystem::exists(levels / "default.json")) << levels;
    // Nothing beside the executable: the working folder's levels/, then the folder itself.
    EXPECT_EQ(findLevelsDirectory({}, elsewhere.path), std::filesystem::absolute(elsewhere.path));
    // Save as asks before writing over another file, not over the document's own.
    const std::filesystem::path mine = elsewhere.path / "mine.json", other = elsewhere.path / "other.json";
    std::ofstream(mine) << "{}";
    std::ofstream(other) << "{}";
    EXPECT_TRUE(replacesAnotherFile(other, mine));
    EXPECT_FALSE(replacesAnotherFile(mine, mine));
    EXPECT_FALSE(replacesAnotherFile(elsewhere.path / "new.json", mine));
    EXPECT_TRUE(replacesAnotherFile(other, {}));  // untitled
    EXPECT_EQ(dialogFolder(mine, levels), std::filesystem::absolute(elsewhere.path));
    EXPECT_EQ(dialogFolder({}, levels), levels);
}
