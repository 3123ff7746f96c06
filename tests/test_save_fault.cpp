// Saves under fault: a process saving a level is killed with
// SIGKILL at random points, hundreds of times. After every kill the level on
// disk is exactly the old bytes or exactly the new bytes, and it loads.
// Temporaries a killed save leaves behind are hidden, never loaded, and
// removed by a later save once they are an hour old (scene_file.cpp).

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

using namespace stepwise;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

using stepwise::test::readFile;

fs::path freshDir(const std::string& name) {
    fs::path dir = fs::temp_directory_path() / ("stepwise_fault_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

/// A level of about 60 KB (15 pages), with `variant` changing both content
/// and length, so a file cut short or mixed from both versions cannot pass
/// for either. Long names make the bytes without many entities: building
/// the text is the part of a save before the temporary exists, and it
/// costs per entity and per byte (under ASan 15 ms for 200 KB), while
/// fsync, the longest step of the window that matters, costs the same for
/// any size. At 60 KB most kills land between mkstemp and the folder's
/// fsync.
Scene bigScene(int entities, int variant) {
    Scene scene;
    scene.world.time = variant;
    for (int i = 0; i < entities + variant * 7; ++i) {
        const Entity e = scene.registry.create();
        scene.registry.emplace<Name>(e, Name{"body" + std::to_string(i) + std::string(2000, char('a' + variant))});
        scene.registry.emplace<Position>(e, Position{{i * 0.1 + variant, -i * 0.3 / 7.0}});
        scene.registry.emplace<Velocity>(e, Velocity{{variant * 0.5, i / 3.0}});
        scene.registry.emplace<Radius>(e, Radius{0.05 + 0.001 * (i % 13)});
    }
    return scene;
}

std::vector<fs::path> temporariesIn(const fs::path& dir) {
    std::vector<fs::path> out;
    for (const auto& entry : fs::directory_iterator(dir))
        if (entry.path().filename() != "level.json") out.push_back(entry.path());
    return out;
}

} // namespace

TEST(SaveUnderFault, SigkillAtRandomPointsLeavesEitherTheOldOrTheNewFileNeverAPartialOne) {
    constexpr int kKills = 300;
    const fs::path dir = freshDir("kill");
    const fs::path level = dir / "level.json";
    const Scene scenes[2] = {bigScene(30, 0), bigScene(30, 1)};
    const std::string bytes[2] = {sceneToJsonText(scenes[0]), sceneToJsonText(scenes[1])};
    ASSERT_NE(bytes[0].size(), bytes[1].size());
    // Both versions load; after each kill the file must equal one of them
    // byte for byte, which (parsing being deterministic) means it loads too.
    for (const std::string& version : bytes) {
        Result<Scene> loaded = parseScene(version, "level.json");
        ASSERT_TRUE(loaded) << loaded.error();
    }
    ASSERT_TRUE(saveSceneFile(scenes[0], level));

    // Where a save spends its time here (sanitizers make building the text
    // several times slower): first building the text, then the window
    // that matters, mkstemp .. write .. fsync .. rename .. fsync(folder).
    // Half the kills are spread over two whole saves. The other half aim at
    // that window, which is short next to the jitter of building the text
    // on a loaded machine, so the aim follows the outcomes: a kill that
    // left the file unchanged and no temporary was too early, one that
    // found the file changed was too late. Both "killed with a temporary
    // half written" and "killed just after the rename" then happen many
    // times in every run, however fast this machine is.
    const auto micros = [](Clock::duration d) {
        return std::chrono::duration_cast<std::chrono::microseconds>(d).count();
    };
    long long textMicros = 0, writeMicros = 0;
    for (int i = 0; i < 4; ++i) {
        const auto t0 = Clock::now();
        const std::string text = sceneToJsonText(scenes[(i + 1) % 2]);
        const auto t1 = Clock::now();
        ASSERT_TRUE(saveSceneFile(scenes[(i + 1) % 2], level));
        const auto t2 = Clock::now();
        textMicros += micros(t1 - t0) / 4;
        writeMicros += std::max<long long>(0, micros(t2 - t1) - micros(t1 - t0)) / 4;
    }
    writeMicros = std::max<long long>(writeMicros, 100);
    ASSERT_EQ(readFile(level), bytes[0]);

    const unsigned seed = std::random_device{}();
    SCOPED_TRACE("seed " + std::to_string(seed) + "; a save takes " + std::to_string(textMicros) +
                 " us building text, then " + std::to_string(writeMicros) + " us writing");
    std::mt19937 rng(seed);
    std::uniform_int_distribution<long long> anywhere(0, 2 * (textMicros + writeMicros));
    std::uniform_int_distribution<long long> jitter(-writeMicros / 2, writeMicros / 2);
    long long aim = textMicros + writeMicros / 2;
    const long long aimStep = std::max<long long>(writeMicros / 4, 50);
    const auto delay = [&](int kill) { return std::max<long long>(0, kill % 2 ? aim + jitter(rng) : anywhere(rng)); };

    int onDisk = 0;  // which version the file holds
    int changed = 0, killedMidSave = 0;
    for (int kill = 0; kill < kKills; ++kill) {
        // The child warms up with a save of the bytes already on disk, then
        // alternates versions forever, starting with the one not on disk, so
        // every completed rename changes the file.
        int k = 0;
        const std::string killed = stepwise::test::killWhileWorking(
            [&] { return bool(saveSceneFile(scenes[onDisk], level)); },
            [&] { return bool(saveSceneFile(scenes[(onDisk + ++k) % 2], level)); },
            std::chrono::microseconds(delay(kill)));
        ASSERT_EQ(killed, "") << "kill " << kill;

        const std::string now = readFile(level);
        ASSERT_TRUE(now == bytes[0] || now == bytes[1])
            << "kill " << kill << ": the file is neither version (" << now.size() << " bytes; the versions have "
            << bytes[0].size() << " and " << bytes[1].size() << ")";

        const int version = now == bytes[0] ? 0 : 1;
        changed += version != onDisk;
        const bool tooLate = version != onDisk;
        onDisk = version;
        // What a killed save leaves: at most its own temporary, named as
        // writeFileAtomically names them. Removed here so each kill's
        // leftover is counted once.
        const auto leftovers = temporariesIn(dir);
        ASSERT_LE(leftovers.size(), 1u) << "kill " << kill;
        for (const fs::path& tmp : leftovers) {
            const std::string name = tmp.filename().string();
            EXPECT_EQ(name.rfind(".level.json.tmp-", 0), 0u) << name;
            EXPECT_EQ(name.size(), std::string(".level.json.tmp-XXXXXX").size()) << name;
            ++killedMidSave;
            fs::remove(tmp);
        }
        if (kill % 2 && leftovers.empty()) aim = std::max<long long>(0, aim + (tooLate ? -aimStep : aimStep));
    }
    // The kills must have hit both sides of the rename, or the loop proved
    // nothing: some after a completed save, some with a temporary in the
    // middle of being written. At least 5% each; measured with the aim
    // following the outcomes: 48 kills left a temporary and 120 found the
    // file changed under ASan, 125 and 134 in Release (of 300).
    EXPECT_GE(changed, kKills / 20) << "too few kills landed after a completed save";
    EXPECT_GE(killedMidSave, kKills / 20) << "too few kills landed inside a save";
    RecordProperty("kills", kKills);
    RecordProperty("killed_mid_save", killedMidSave);
    RecordProperty("file_changed", changed);
    fs::remove_all(dir);
}

TEST(SaveUnderFault, ASaveRemovesOnlyItsOwnTemporariesOlderThanAnHour) {
    const fs::path dir = freshDir("stale");
    const fs::path level = dir / "level.json";
    const auto touch = [&](const std::string& name, std::chrono::minutes age) {
        const fs::path p = dir / name;
        std::ofstream(p) << "{\"entities\": [";  // what a killed save leaves: a prefix
        fs::last_write_time(p, fs::file_time_type::clock::now() - age);
        return p;
    };
    const fs::path stale = touch(".level.json.tmp-a1B2c3", std::chrono::minutes(61));
    const fs::path young = touch(".level.json.tmp-d4E5f6", std::chrono::minutes(59));       // maybe a live save
    const fs::path other = touch(".other.json.tmp-g7H8i9", std::chrono::minutes(600));      // another level's
    const fs::path longer = touch(".level.json.tmp-a1B2c3x", std::chrono::minutes(600));    // not our pattern
    const fs::path designer = touch("level.json.tmp-a1B2c3", std::chrono::minutes(600));    // not hidden: a user's
    ASSERT_TRUE(saveSceneFile(bigScene(3, 0), level));
    EXPECT_FALSE(fs::exists(stale));
    EXPECT_TRUE(fs::exists(young));
    EXPECT_TRUE(fs::exists(other));
    EXPECT_TRUE(fs::exists(longer));
    EXPECT_TRUE(fs::exists(designer));
    fs::remove_all(dir);
}
