// The `stepwise` command line as a user meets it: exit codes, messages on
// stderr, outputs written or not written, same bytes for the same input.

#include "stepwise/scene_io.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <sys/resource.h>
#include <sys/stat.h>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

struct Outcome {
    int exitCode = -1;
    std::string out;
    std::string err;
};

using stepwise::test::readFile;

class Cli : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("stepwise_cli_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    /// Runs build/stepwise with `args` (shell words), capturing both streams.
    Outcome stepwise(const std::string& args) {
        const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
        const std::string command = std::string(STEPWISE_BINARY) + " " + args + " >" + out.string() + " 2>" +
                                    err.string() + " </dev/null";
        const int status = std::system(command.c_str());
        Outcome o;
        o.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        o.out = readFile(out);
        o.err = readFile(err);
        fs::remove(out);
        fs::remove(err);
        return o;
    }
    /// Peak resident memory (KiB) of `stepwise ARGS`, the process itself
    /// (exec'd by the shell, so the shell's own memory does not count).
    long peakKib(const std::string& args) {
        const std::string command = "exec " + std::string(STEPWISE_BINARY) + " " + args + " >/dev/null 2>&1";
        const pid_t child = ::fork();
        if (child == 0) {
            ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
            _exit(127);
        }
        int status = 0;
        struct rusage usage {};
        if (::wait4(child, &status, 0, &usage) != child) return -1;
        return usage.ru_maxrss;
    }
    fs::path write(const std::string& name, const std::string& text) {
        const fs::path p = dir_ / name;
        std::ofstream(p, std::ios::binary) << text;
        return p;
    }
    std::string level(const std::string& name) const {
        return (fs::path(STEPWISE_SOURCE_DIR) / "levels" / name).string();
    }

    fs::path dir_;
};

// A shape-free scene with every force kind the engine has: gravity, drag,
// springs (body-body and anchored) and an attractor.
const char* kForces = R"({
  "world": {"gravity": {"x": 0, "y": -9.81}, "integrator": "rk4", "dt": 0.01},
  "entities": [
    {"name": "sun", "position": {"x": 0, "y": 0}, "mass": 50, "static": true, "attractor": {"softening": 0.1}},
    {"name": "p", "position": {"x": 3, "y": 0}, "velocity": {"x": 0, "y": 4}, "drag": 0.05},
    {"name": "q", "position": {"x": 3.5, "y": 0.5}, "mass": 0.5},
    {"name": "pq", "spring": {"a": "p", "b": "q", "k": 40, "damping": 0.2}},
    {"name": "hang", "spring": {"a": "q", "anchor": {"x": 4, "y": 2}, "k": 10, "rest_length": 1}}
  ]
})";

} // namespace

TEST_F(Cli, ValidatePrintsASummaryOfAGoodLevel) {
    const fs::path file = write("forces.json", kForces);
    Outcome o = stepwise("validate " + file.string());
    EXPECT_EQ(o.exitCode, 0) << o.err;
    EXPECT_EQ(o.out.rfind(file.string() + ": ok: 5 entities; components: name x5, position x3, velocity x1, mass x2, "
                                          "static x1, drag x1, attractor x1, spring x2; systems: ",
                          0),
              0u)
        << o.out;
    for (const char* system : {"gravity", "drag", "springs", "attractors"})
        EXPECT_NE(o.out.find(system), std::string::npos) << system << " missing from: " << o.out;
    EXPECT_EQ(o.out.find("boids"), std::string::npos) << "a scene without boids must not run the boid system";
}

TEST_F(Cli, ValidateWarnsAboutComponentsThatHaveNoEffect) {
    const fs::path file = write("ineffective.json", R"({"entities": [
      {"name": "wall", "position": {"x": 0, "y": 0}, "static": true, "velocity": {"x": 1, "y": 0}, "mass": 3},
      {"name": "sun", "position": {"x": 5, "y": 0}, "static": true, "mass": 50, "attractor": {}},
      {"name": "dot", "position": {"x": 0, "y": 2}, "friction": 0.5}]})");
    Outcome o = stepwise("validate " + file.string());
    EXPECT_EQ(o.exitCode, 0) << "a valid file stays valid; the notes are warnings";
    EXPECT_EQ(o.err, file.string() + ": warning: entity 0 (\"wall\"): \"velocity\" on a static body has no effect "
                                     "(static bodies never move)\n" +
                         file.string() + ": warning: entity 0 (\"wall\"): \"mass\" on a static body has no effect "
                                         "(static mass is infinite)\n" +
                         file.string() + ": warning: entity 2 (\"dot\"): \"friction\" has no effect: the entity has "
                                         "no shape, so it never collides\n")
        << "a static attractor's mass sets its pull, so it gets no warning";
}

TEST_F(Cli, ValidateWarnsAboutWhatAKinematicBodyIgnores) {
    const fs::path file = write("kinematic_notes.json", R"({"entities": [
      {"name": "lift", "position": {"x": 0, "y": 0}, "kinematic": true, "mass": 3, "drag": 1, "boid": {}},
      {"name": "moon", "position": {"x": 5, "y": 0}, "kinematic": true, "mass": 50, "attractor": {}}]})");
    Outcome o = stepwise("validate " + file.string());
    EXPECT_EQ(o.exitCode, 0);
    const std::string head = file.string() + ": warning: entity 0 (\"lift\"): ";
    EXPECT_EQ(o.err, head + "\"mass\" on a kinematic body has no effect (its mass is infinite)\n" + head +
                         "\"drag\" on a kinematic body has no effect (only its velocity moves it)\n" + head +
                         "\"boid\" on a kinematic body has no effect (only its velocity moves it)\n")
        << "a kinematic attractor's mass sets its pull, so it gets no warning";
}

// In range field by field, yet no step could take it: validate and run
// refuse it alike, with exit 2 and the same words.
TEST_F(Cli, ALevelNoStepCanTakeIsRefusedByValidateAndRun) {
    const fs::path file = write("heavy_gravity.json", R"({"world": {"gravity": {"x": 0, "y": -1e30}},
      "entities": [{"name": "ball", "position": {"x": 0, "y": 0}, "radius": 0.5}]})");
    const std::string why = "world.gravity: 1e+30 m/s^2 gives a body 1.6666666666666667e+28 m/s in one step of "
                            "0.016666666666666666 s, past the 1e+09 m/s a run holds; at this dt gravity may be at "
                            "most 6e+10 m/s^2";
    for (const std::string command : {"validate ", "run --steps 3 "}) {
        Outcome o = stepwise(command + file.string());
        EXPECT_EQ(o.exitCode, 2) << command;
        EXPECT_EQ(o.out, "") << command;
        EXPECT_EQ(o.err, "stepwise: error: " + file.string() + ": cannot simulate: " + why + "\n") << command;
    }
}

TEST_F(Cli, ValidateRefusesABadFileWithExitTwoAndTheLoaderMessage) {
    const fs::path file = write("bad.json", R"({"entities": [{"name": "ball", "position": {"x": 0, "y": 0}, "mass": -1}]})");
    Outcome o = stepwise("validate " + file.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, file.string() + ": error: /entities/0/mass: expected a number in [1e-30, 1e+30], got -1\n");
    EXPECT_EQ(o.out, "");
}

TEST_F(Cli, ValidateMissingFile) {
    Outcome o = stepwise("validate " + (dir_ / "nope.json").string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, (dir_ / "nope.json").string() + ": error: no such file\n");
}

TEST_F(Cli, BadArgumentsExitTwoNamingTheArgument) {
    const fs::path file = write("forces.json", kForces);
    Outcome o = stepwise("run " + file.string() + " --steps -5");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_NE(o.err.find("--steps"), std::string::npos) << o.err;
    o = stepwise("run " + file.string() + " --steps 10 --integrator rk5");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_NE(o.err.find("--integrator: rk5 not in {explicit_euler,semi_implicit_euler,"), std::string::npos) << o.err;
    o = stepwise("run " + file.string() + " --steps 10 --dt 0");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_NE(o.err.find("--dt"), std::string::npos) << o.err;
    o = stepwise("run " + file.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_NE(o.err.find("--steps is required"), std::string::npos) << o.err;
    o = stepwise("frobnicate");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_NE(o.err.find("frobnicate"), std::string::npos) << o.err;
}

TEST_F(Cli, RunWritesTheSceneWithTimeAdvanced) {
    const fs::path file = write("forces.json", kForces), out = dir_ / "out.json";
    Outcome o = stepwise("run " + file.string() + " --steps 100 --out " + out.string());
    ASSERT_EQ(o.exitCode, 0) << o.err;
    const std::string saved = readFile(out);
    EXPECT_NE(saved.find("\"time\": 1.0000000000000007"), std::string::npos)
        << "100 additions of 0.01 give this double exactly:\n" << saved.substr(0, 300);
    EXPECT_NE(saved.find("\"integrator\": \"rk4\""), std::string::npos);
}

TEST_F(Cli, SameInputGivesTheSameBytes) {
    const fs::path file = write("forces.json", kForces);
    const fs::path a = dir_ / "a.json", b = dir_ / "b.json", ta = dir_ / "a.csv", tb = dir_ / "b.csv";
    ASSERT_EQ(stepwise("run " + file.string() + " --steps 150 --out " + a.string() + " --trace " + ta.string()).exitCode, 0);
    ASSERT_EQ(stepwise("run " + file.string() + " --steps 150 --out " + b.string() + " --trace " + tb.string()).exitCode, 0);
    EXPECT_EQ(readFile(a), readFile(b));
    EXPECT_EQ(readFile(ta), readFile(tb));
}

TEST_F(Cli, TwoHundredStepsEqualHundredSavedLoadedAndHundredMore) {
    for (const char* integrator : {"semi_implicit_euler", "rk4", "velocity_verlet", "implicit_euler"}) {
        const fs::path file = write("forces.json", kForces);
        const fs::path whole = dir_ / "whole.json", half = dir_ / "half.json", resumed = dir_ / "resumed.json";
        const std::string common = std::string(" --integrator ") + integrator;
        ASSERT_EQ(stepwise("run " + file.string() + " --steps 200 --out " + whole.string() + common).exitCode, 0);
        ASSERT_EQ(stepwise("run " + file.string() + " --steps 100 --out " + half.string() + common).exitCode, 0);
        ASSERT_EQ(stepwise("run " + half.string() + " --steps 100 --out " + resumed.string() + common).exitCode, 0);
        EXPECT_EQ(readFile(whole), readFile(resumed)) << integrator;
    }
}

TEST_F(Cli, TraceHasARowPerStepPlusTheInitialState) {
    const fs::path file = write("forces.json", kForces), trace = dir_ / "t.csv";
    ASSERT_EQ(stepwise("run " + file.string() + " --steps 25 --trace " + trace.string()).exitCode, 0);
    std::istringstream lines(readFile(trace));
    std::string header, line;
    std::getline(lines, header);
    EXPECT_EQ(header, "step,time,kinetic,potential_gravity,potential_springs,potential_attractors,potential,total,"
                      "momentum_x,momentum_y,contacts");
    int rows = 0;
    while (std::getline(lines, line)) {
        EXPECT_EQ(line.rfind(std::to_string(rows) + ",", 0), 0u) << line;
        ++rows;
    }
    EXPECT_EQ(rows, 26);
}

TEST_F(Cli, DivergenceExitsThreeNamesTheStepAndWritesNoScene) {
    // h*omega = 0.1*sqrt(1e6) = 100: explicit Euler multiplies the energy by
    // 1 + (h omega)^2 every step, so it overflows within a few hundred steps.
    const fs::path file = write("stiff.json", R"({"world": {"gravity": {"x": 0, "y": 0}, "dt": 0.1, "integrator": "explicit_euler"},
      "entities": [{"name": "bob", "position": {"x": 1.5, "y": 0}},
                   {"name": "s", "spring": {"a": "bob", "anchor": {"x": 0, "y": 0}, "k": 1e6, "rest_length": 1}}]})");
    const fs::path out = dir_ / "out.json";
    Outcome o = stepwise("run " + file.string() + " --steps 10000 --out " + out.string());
    EXPECT_EQ(o.exitCode, 3) << o.err;
    EXPECT_NE(o.err.find("simulation diverged at step "), std::string::npos) << o.err;
    EXPECT_NE(o.err.find("entity 0 (\"bob\")"), std::string::npos) << o.err;
    EXPECT_NE(o.err.find("--out not written"), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(out));
}

TEST_F(Cli, UnwritableOutputIsAClearErrorAndLeavesNothing) {
    const fs::path file = write("forces.json", kForces);
    Outcome o = stepwise("run " + file.string() + " --steps 3 --out " + (dir_ / "missing" / "o.json").string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, (dir_ / "missing" / "o.json").string() + ": error: cannot write: No such file or directory\n");
}

TEST_F(Cli, RunsTheCourseNotesLevel) {
    const fs::path out = dir_ / "out.json";
    Outcome o = stepwise("run " + level("course_notes.json") + " --steps 60 --out " + out.string());
    EXPECT_EQ(o.exitCode, 0) << o.err;
    // 60 additions of 1/60 in doubles give this value exactly.
    EXPECT_NE(readFile(out).find("\"time\": 1.0000000000000013"), std::string::npos) << readFile(out);
}

TEST_F(Cli, ContactsFileHasOneLinePerStepWithEveryContact) {
    // A ball dropped from 0.1 m onto a plane: airborne for 0.14 s (8 steps),
    // then resting on it with one contact.
    const fs::path file = write("drop.json", R"({"world": {"gravity": {"x": 0, "y": -10}},
      "entities": [{"name": "floor", "plane": {"normal": {"x": 0, "y": 1}, "offset": 0}},
                   {"name": "ball", "position": {"x": 0, "y": 0.6}, "radius": 0.5}]})");
    const fs::path contacts = dir_ / "contacts.jsonl";
    Outcome o = stepwise("run " + file.string() + " --steps 30 --contacts " + contacts.string());
    ASSERT_EQ(o.exitCode, 0) << o.err;
    std::istringstream lines(readFile(contacts));
    std::string line, last;
    int count = 0, touching = 0;
    while (std::getline(lines, line)) {
        last = line;
        ++count;
        EXPECT_EQ(line.rfind("{\"step\": " + std::to_string(count) + ", \"time\": ", 0), 0u) << line;
        if (line.find("\"a\": \"ball\", \"b\": \"floor\"") != std::string::npos) ++touching;
    }
    EXPECT_EQ(count, 30);
    EXPECT_GE(touching, 20) << "the ball rests on the floor for the last 20 steps at least";
    // The static side is b and the normal points from a to b (+ 0.0 keeps
    // a -0 out of the file).
    EXPECT_NE(last.find("\"normal\": {\"x\": 0, \"y\": -1}"), std::string::npos) << last;
}

// Two weights on hinges with max_force 100 N under 10 m/s^2: the 15 kg one
// breaks its hook after the first step, the 5 kg one holds. The contacts
// trace gets one break line, stderr a note, the summary a count; the saved
// file no longer holds the broken hook and resumes exactly, with a spring
// on the hinge that holds.
TEST_F(Cli, ABreakingJointIsReportedInTheTraceAndStderrAndLeavesTheSavedFile) {
    const fs::path file = write("hooks.json", R"({"world": {"gravity": {"x": 0, "y": -10}, "substeps": 4},
      "entities": [{"name": "heavy", "position": {"x": -2, "y": -1}, "mass": 15, "radius": 0.2},
                   {"name": "light", "position": {"x": 2, "y": -1}, "angle": 0.2, "mass": 5, "radius": 0.2},
                   {"name": "weak hook", "joint": {"type": "hinge", "a": "heavy", "anchor": {"x": -2, "y": 0},
                                                   "max_force": 100}},
                   {"name": "strong hook", "joint": {"type": "hinge", "a": "light", "anchor": {"x": 2, "y": 0},
                                                     "reference_angle": 0, "spring_hz": 3, "spring_damping_ratio": 0.1,
                                                     "max_force": 100}}]})");
    const fs::path contacts = dir_ / "c.jsonl", whole = dir_ / "whole.json", half = dir_ / "half.json",
                   resumed = dir_ / "resumed.json";
    Outcome o = stepwise("run " + file.string() + " --steps 60 --contacts " + contacts.string() + " --out " +
                         whole.string());
    ASSERT_EQ(o.exitCode, 0) << o.err;
    EXPECT_EQ(o.err, file.string() + ": note: step 1: joint \"weak hook\" broke: force 150 N past its max_force 100 N\n");
    EXPECT_NE(o.out.find("; 1 joint broke; wrote "), std::string::npos) << o.out;
    std::istringstream lines(readFile(contacts));
    std::string line;
    std::vector<std::string> breaks;
    int steps = 0;
    while (std::getline(lines, line)) {
        if (line.rfind("{\"event\": \"break\"", 0) == 0) breaks.push_back(line);
        else ++steps;
    }
    EXPECT_EQ(steps, 60);
    ASSERT_EQ(breaks.size(), 1u);
    EXPECT_EQ(breaks[0].rfind(R"({"event": "break", "step": 1, "time": 0.016666666666666666, "joint": "weak hook", )"
                              R"("a": "heavy", "b": null, "force": 15)",
                              0),
              0u)
        << breaks[0];
    EXPECT_NE(breaks[0].find(R"("max_force": 100})"), std::string::npos) << breaks[0];
    const std::string saved = readFile(whole);
    EXPECT_EQ(saved.find("weak hook"), std::string::npos) << "the broken joint left the scene";
    EXPECT_NE(saved.find("strong hook"), std::string::npos);
    EXPECT_NE(saved.find(R"({"joint": "strong hook", "linear_impulse")"), std::string::npos) << saved;
    EXPECT_NE(saved.find(R"("angular_impulse")"), std::string::npos) << "the spring's warm start is saved";
    ASSERT_EQ(stepwise("run " + file.string() + " --steps 30 --out " + half.string()).exitCode, 0);
    o = stepwise("run " + half.string() + " --steps 30 --out " + resumed.string());
    ASSERT_EQ(o.exitCode, 0) << o.err;
    EXPECT_EQ(o.err, "") << "nothing left to break";
    EXPECT_EQ(readFile(whole), readFile(resumed));
}

TEST_F(Cli, SchemaCommandMatchesTheCommittedSchema) {
    Outcome o = stepwise("schema");
    ASSERT_EQ(o.exitCode, 0);
    EXPECT_EQ(o.out, readFile(level("scene.schema.json")))
        << "levels/scene.schema.json is stale: regenerate it with `build/stepwise schema --out levels/scene.schema.json`";
}

TEST_F(Cli, EverySubcommandHasHelp) {
    for (const char* sub : {"validate", "run", "schema"}) {
        Outcome o = stepwise(std::string(sub) + " --help");
        EXPECT_EQ(o.exitCode, 0) << sub;
        EXPECT_NE(o.out.find("Usage:"), std::string::npos) << sub << ": " << o.out;
    }
}

// ---- Limits and bad input everywhere ----------------------------------------

TEST_F(Cli, ValidateRefusesOneEntityPastTheDocumentedLimitAndAcceptsTheLimit) {
    // docs/format.md, "Limits": 1,000,000 entities. Empty entities keep the file at
    // 3 MB; the count is checked while parsing.
    const auto levelWith = [&](std::size_t n) {
        std::string text = "{\"entities\": [";
        text.reserve(16 + 3 * n);
        for (std::size_t i = 0; i < n; ++i) text += i ? ",{}" : "{}";
        return write("n" + std::to_string(n) + ".json", text + "]}\n");
    };
    const fs::path over = levelWith(1'000'001);
    Outcome o = stepwise("validate " + over.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, over.string() + ": error: more than 1000000 entities; the limit is 1000000\n");
    EXPECT_EQ(o.out, "");
    const fs::path at = levelWith(1'000'000);
    o = stepwise("validate " + at.string());
    EXPECT_EQ(o.exitCode, 0) << o.err;
    EXPECT_EQ(o.out, at.string() + ": ok: 1000000 entities; components: none; systems: none; integrator "
                                   "semi_implicit_euler\n");
}

// Outputs are written through symbolic links: a linked output stays a link
// and its target gets the bytes, and a dangling link counts as the file it
// points at, so it cannot be the --trace file as well.
TEST_F(Cli, OutputsAreWrittenThroughSymbolicLinks) {
    const fs::path real = write("real.json", "{\"entities\": []}\n");
    const fs::path link = dir_ / "link.json";
    fs::create_symlink("real.json", link);
    Outcome o = stepwise("run " + level("orbit.json") + " --steps 2 --out " + link.string());
    ASSERT_EQ(o.exitCode, 0) << o.err;
    EXPECT_TRUE(fs::is_symlink(link));
    EXPECT_EQ(fs::read_symlink(link), fs::path("real.json"));
    stepwise::Result<stepwise::Scene> written = stepwise::loadSceneFile(real);
    ASSERT_TRUE(written) << written.error();
    EXPECT_GT(written->registry.size(), 0u) << "the target holds the run";

    const fs::path dangling = dir_ / "dangling.json";
    fs::create_symlink("t.csv", dangling);
    o = stepwise("run " + level("orbit.json") + " --steps 2 --out " + dangling.string() + " --trace " +
                 (dir_ / "t.csv").string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, "stepwise: error: --trace: " + (dir_ / "t.csv").string() + " is the same file as --out " +
                         dangling.string() + "; give each output its own file\n");
    EXPECT_FALSE(fs::exists(dir_ / "t.csv"));
    // A dangling link to a new file in an existing folder creates that file.
    const fs::path fresh = dir_ / "fresh.json";
    fs::create_symlink("made.json", fresh);
    o = stepwise("run " + level("orbit.json") + " --steps 1 --out " + fresh.string());
    ASSERT_EQ(o.exitCode, 0) << o.err;
    EXPECT_TRUE(fs::is_symlink(fresh));
    EXPECT_TRUE(fs::is_regular_file(dir_ / "made.json"));
}

TEST_F(Cli, ValidateRefusesAFileOverTheSizeLimitBeforeReadingIt) {
    const fs::path huge = write("huge.json", "{}");
    fs::resize_file(huge, (256ull << 20) + 1);  // sparse: no disk, and never read
    Outcome o = stepwise("validate " + huge.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, huge.string() + ": error: file is 268435457 bytes; the limit is 268435456 bytes\n");
}

TEST_F(Cli, ValidateAndSchemaBadArguments) {
    Outcome o = stepwise("validate");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err.rfind("LEVEL is required\n", 0), 0u) << o.err;
    o = stepwise("validate " + level("orbit.json") + " extra.json");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err.rfind("The following argument was not expected: extra.json\n", 0), 0u) << o.err;

    o = stepwise("schema extra");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err.rfind("The following argument was not expected: extra\n", 0), 0u) << o.err;
    o = stepwise("schema --bogus");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err.rfind("The following argument was not expected: --bogus\n", 0), 0u) << o.err;
    // --out under a regular file, and --out naming a folder: the message
    // names the path given, and nothing is written.
    const fs::path file = write("file.txt", "keep");
    o = stepwise("schema --out " + (file / "s.json").string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, (file / "s.json").string() + ": error: cannot write: Not a directory\n");
    o = stepwise("schema --out " + dir_.string());
    EXPECT_EQ(o.exitCode, 2);
    // (Found by the check before writing, in the words of the other
    // unwritable targets, not by the rename.)
    EXPECT_EQ(o.err, dir_.string() + ": error: cannot write: Is a directory\n");
    EXPECT_EQ(readFile(file), "keep");
    EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1) << "a temporary was left";
}

TEST_F(Cli, RunBadArgumentsNameTheArgument) {
    const fs::path file = write("forces.json", kForces);
    Outcome o = stepwise("run " + file.string() + " --steps -5");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err.rfind("--steps: expected a whole number >= 0, got \"-5\"\n", 0), 0u) << o.err;
    o = stepwise("run " + file.string() + " --steps abc");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err.rfind("--steps: expected a whole number >= 0, got \"abc\"\n", 0), 0u) << o.err;
    o = stepwise("run " + file.string() + " --steps 99999999999999999999");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err.rfind("--steps: expected a whole number >= 0, got \"99999999999999999999\"\n", 0), 0u) << o.err;
    const fs::path notAFolder = write("file.txt", "");
    for (const char* option : {"--out", "--trace", "--contacts"}) {
        const fs::path target = notAFolder / "x";
        o = stepwise("run " + file.string() + " --steps 2 " + option + " " + target.string());
        EXPECT_EQ(o.exitCode, 2) << option;
        EXPECT_EQ(o.err, target.string() + ": error: cannot write: Not a directory\n") << option;
    }
}

TEST_F(Cli, RenderBadArgumentsExitTwoNameTheArgumentAndWriteNothing) {
    const std::string orbit = level("orbit.json");
    const fs::path png = dir_ / "x.png";
    const fs::path notAFolder = write("file.txt", "");
    struct Case {
        std::string args;
        std::string firstLine;  // exact first line of stderr
    };
    const std::vector<Case> cases = {
        {orbit, "--out is required"},
        {orbit + " --out " + png.string() + " --steps -1", "--steps: expected a whole number >= 0, got \"-1\""},
        {orbit + " --out " + png.string() + " --steps 1.5", "--steps: expected a whole number >= 0, got \"1.5\""},
        {orbit + " --out " + png.string() + " --width 8", "--width: Value 8 not in range 16 to 16384"},
        {orbit + " --out " + png.string() + " --height 20000", "--height: Value 20000 not in range 16 to 16384"},
        {orbit + " --out " + png.string() + " --frames 0", "--frames: Value 0 not in range 1 to 100000"},
        {orbit + " --out " + png.string() + " --every 0", "--every: Value 0 not in range 1 to 1000000000"},
        {orbit + " --out " + png.string() + " --trail 1", "--trail: Value 1 not in range 2 to 100000"},
        {orbit + " --out " + png.string() + " --integrator rk5",
         "--integrator: rk5 not in {explicit_euler,semi_implicit_euler,midpoint,trapezoid,rk4,velocity_verlet,"
         "implicit_euler,implicit_midpoint,dopri5}"},
        {orbit + " --out " + png.string() + " --overlay velocity,bogus",
         "stepwise: error: --overlay: unknown overlay \"bogus\"; known overlays: velocity, velocity-field, "
         "force-field, force, net-force, contacts, aabb, trails, joints, all, none"},
        {orbit + " --out " + png.string() + " --camera 1,2",
         "stepwise: error: --camera: expected X,Y,ZOOM (metres, metres, pixels per metre at 720 px height), got "
         "\"1,2\""},
        {orbit + " --out " + png.string() + " --camera 1,2,0", "stepwise: error: --camera: ZOOM must be > 0, got 0"},
        {orbit + " --out " + png.string() + " --camera 1,2,nan",
         "stepwise: error: --camera: expected X,Y,ZOOM (metres, metres, pixels per metre at 720 px height), got "
         "\"1,2,nan\""},
        {orbit + " --out " + png.string() + " --select sun,nobody",
         "stepwise: error: --select: " + orbit + " has no entity named \"nobody\""},
        {orbit + " --out " + png.string() + " --steps 9223372036854775807 --frames 3 --every 5",
         "stepwise: error: --steps: 9223372036854775807 plus 2 x --every 5 steps does not fit in a 64-bit count"},
        {orbit + " --out " + (dir_ / "missing" / "x.png").string(),
         "stepwise: error: --out: folder " + (dir_ / "missing").string() + " does not exist"},
        {orbit + " --out " + (notAFolder / "x.png").string(),
         "stepwise: error: --out: folder " + notAFolder.string() + " is not a folder"},
        {(dir_ / "nope.json").string() + " --out " + png.string(), (dir_ / "nope.json").string() + ": error: no such file"},
        {orbit + " --out " + png.string() + " --bogus", "The following argument was not expected: --bogus"},
    };
    for (const Case& c : cases) {
        Outcome o = stepwise("render " + c.args);
        EXPECT_EQ(o.exitCode, 2) << c.args << "\n" << o.err;
        EXPECT_EQ(o.err.substr(0, o.err.find('\n')), c.firstLine) << c.args;
        EXPECT_FALSE(fs::exists(png)) << c.args;
    }
}

/// Runs `stepwise ARGS` as the unprivileged user nobody when this process
/// is root (root may write any file, so a read-only file means nothing to
/// it). The shell that redirects stderr to `errFile` stays root.
Outcome stepwiseUnprivileged(const std::string& args, const fs::path& errFile) {
    const std::string asNobody = ::geteuid() == 0 ? "setpriv --reuid=65534 --regid=65534 --clear-groups " : "";
    const int status =
        std::system((asNobody + STEPWISE_BINARY + " " + args + " >/dev/null 2>" + errFile.string()).c_str());
    Outcome o;
    o.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    o.err = readFile(errFile);
    return o;
}

TEST_F(Cli, BenchBadArgumentsExitTwoNamingTheArgument) {
    Outcome o = stepwise("bench");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, "stepwise: error: bench: expected a report to run: accuracy or hard-cases (see stepwise bench --help)\n");
    o = stepwise("bench frob");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, "stepwise: error: bench: unknown report \"frob\"; expected one of: accuracy, hard-cases\n");
    o = stepwise("bench accuracy --quick");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err.rfind("--out is required\n", 0), 0u) << o.err;
    o = stepwise("bench accuracy --quick --out");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err.rfind("--out: 1 required TEXT missing\n", 0), 0u) << o.err;
    o = stepwise("bench accuracy --quick --out " + (dir_ / "r").string() + " --repeat 3");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err.rfind("The following arguments were not expected: 3 --repeat\n", 0), 0u) << o.err;
    // Checked before any measuring: fails at once and creates nothing. The
    // folder must exist, as for every other output.
    const fs::path notAFolder = write("file.txt", "");
    o = stepwise("bench accuracy --quick --out " + (notAFolder / "report").string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, "stepwise: error: --out: " + (notAFolder / "report").string() + " is not an existing folder\n");
    o = stepwise("bench accuracy --quick --out " + notAFolder.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, "stepwise: error: --out: " + notAFolder.string() + " is not an existing folder\n");
    o = stepwise("bench accuracy --quick --out " + (dir_ / "missing" / "report").string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, "stepwise: error: --out: " + (dir_ / "missing" / "report").string() + " is not an existing folder\n");
    EXPECT_FALSE(fs::exists(dir_ / "missing"));
    EXPECT_FALSE(fs::exists(dir_ / "r"));
    // A report file the user may not replace (0444, as an unprivileged
    // user): refused before measuring, in the words of every other output,
    // and kept, not overwritten after the whole run.
    fs::permissions(dir_, fs::perms::all);
    const fs::path reportDir = dir_ / "report";
    fs::create_directory(reportDir);
    fs::permissions(reportDir, fs::perms::all);
    const fs::path md = reportDir / "accuracy.md";
    { std::ofstream(md) << "kept\n"; }
    fs::permissions(md, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
    const fs::path errFile = dir_ / "err.txt";
    const Outcome refused = stepwiseUnprivileged("bench accuracy --quick --out " + reportDir.string(), errFile);
    EXPECT_EQ(refused.exitCode, 2);
    EXPECT_EQ(refused.err, md.string() + ": error: cannot write: Permission denied\n");
    EXPECT_EQ(readFile(md), "kept\n");
    EXPECT_EQ(std::distance(fs::directory_iterator(reportDir), fs::directory_iterator()), 1) << "nothing else written";
}

// `bench hard-cases` runs the hard-cases program of the same build and
// writes its three files; a short run of one case holds each setting's row.
TEST_F(Cli, BenchHardCasesWritesTheReportOfTheCasesAsked) {
#ifndef STEPWISE_HAS_HARD_CASES
    GTEST_SKIP() << "configured with STEPWISE_BUILD_BENCH=OFF: no hard-cases program";
#endif
    const fs::path out = dir_ / "hard";
    Outcome o = stepwise("bench hard-cases --only 'disc w0 -20' --steps 4 --out " + out.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, "stepwise: error: --out: " + out.string() + " is not an existing folder\n");
    EXPECT_FALSE(fs::exists(out));
    o = stepwise("bench hard-cases --steps 0 --out " + dir_.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err.rfind("--steps: Value 0 not in range 1 to 1000000", 0), 0u) << o.err;

    fs::create_directory(out);
    o = stepwise("bench hard-cases --only 'disc w0 -20' --steps 4 --out " + out.string());
    ASSERT_EQ(o.exitCode, 0) << o.err;
    EXPECT_NE(o.out.find("wrote " + (out / "hard_cases.md").string()), std::string::npos) << o.out;
    const std::string csv = readFile(out / "hard_cases.csv");
    for (const char* row : {"\"disc w0 -20 rad/s\",\"disc spun onto the floor\",\"Stepwise default\",default,",
                            "\"disc w0 -20 rad/s\",\"disc spun onto the floor\",\"Stepwise\",1,",
                            "\"disc w0 -20 rad/s\",\"disc spun onto the floor\",\"Stepwise\",8,",
                            "\"disc w0 -20 rad/s\",\"disc spun onto the floor\",\"Box2D 2.4.1\",1,"})
        EXPECT_NE(csv.find(row), std::string::npos) << row << " in\n" << csv;
    EXPECT_EQ(csv.find("disc w0 -5 "), std::string::npos) << "only the case asked for";
    const std::string md = readFile(out / "hard_cases.md");
    EXPECT_NE(md.find("by `stepwise bench hard-cases"), std::string::npos) << md.substr(0, 400);
    // The error's label holds '|': escaped, or it would split its table cell.
    EXPECT_NE(md.find(" | \\|rolling speed - (-w0 r/3)\\|, m/s | "), std::string::npos) << md;
    EXPECT_TRUE(fs::file_size(out / "hard_cases.png") > 1000);
}

TEST_F(Cli, RenderAndBenchHaveHelp) {
    for (const char* sub : {"render", "bench", "bench accuracy", "bench hard-cases"}) {
        Outcome o = stepwise(std::string(sub) + " --help");
        EXPECT_EQ(o.exitCode, 0) << sub;
        EXPECT_NE(o.out.find("Usage:"), std::string::npos) << sub << ": " << o.out;
    }
}

// The scripted editor refuses a bad line at run time with the script's
// file:line and what was wrong, and exits 2, as every bad input does.
TEST_F(Cli, EditScriptNamesTheBadLineForAnUnknownSystemOrEntity) {
    const fs::path system = write("system.txt", "play\nsystem gravty off\n");
    Outcome o = stepwise("edit " + level("orbit.json") + " --builtin-font --size 640x400 --config " +
                         (dir_ / "cfg").string() + " --script " + system.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_NE(o.err.find(system.string() + ":2: system: unknown system \"gravty\" (gravity, drag, springs, "
                                           "attractors, boids, collisions)"),
              std::string::npos)
        << o.err;

    const fs::path breakon = write("breakon.txt", "# comment\n\nbreakon plnet\n");
    o = stepwise("edit " + level("orbit.json") + " --builtin-font --size 640x400 --config " +
                 (dir_ / "cfg").string() + " --script " + breakon.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_NE(o.err.find(breakon.string() + ":3: breakon: no entity named \"plnet\""), std::string::npos) << o.err;
}

// `text` types into the Save as field: the dialog opened by ctrl+shift+s
// takes the typed path and saves there. (A `key` line kept its modifiers
// held, ImGui drops typed characters while ctrl is down, and the dialog
// saved over the level under its suggested name instead.)
TEST_F(Cli, EditScriptTextTypesIntoTheSaveAsField) {
    const fs::path mine = dir_ / "mine.json", typed = dir_ / "typed.json";
    fs::copy_file(level("orbit.json"), mine);
    const std::string original = readFile(mine);
    const fs::path script = write("save_as.txt", "key ctrl+shift+s\nwait 2\nkey ctrl+a\ntext \"" + typed.string() +
                                                     "\"\nkey Enter\nwait 2\n");
    Outcome o = stepwise("edit " + mine.string() + " --builtin-font --size 640x400 --config " + (dir_ / "cfg").string() +
                         " --script " + script.string());
    EXPECT_EQ(o.exitCode, 0) << o.err;
    ASSERT_TRUE(fs::exists(typed)) << "nothing saved at the typed path";
    stepwise::Result<stepwise::Scene> saved = stepwise::parseScene(readFile(typed), typed.string());
    ASSERT_TRUE(saved) << saved.error();
    stepwise::Result<stepwise::Scene> before = stepwise::parseScene(original, mine.string());
    ASSERT_TRUE(before);
    EXPECT_EQ(saved->registry.size(), before->registry.size());
    EXPECT_EQ(readFile(mine), original) << "saved over the open level";
}

TEST_F(Cli, ClockwisePolygonExitsTwoNamingTheEntityAndLeavesTheOutputAlone) {
    const fs::path bad = write("cw.json", R"({"entities": [{"name": "wedge", "position": {"x": 0, "y": 0},
      "polygon": {"vertices": [{"x": 0, "y": 0}, {"x": 0, "y": 1}, {"x": 1, "y": 0}]}}]})");
    const fs::path out = write("out.json", "untouched");
    const Outcome o = stepwise("run " + bad.string() + " --steps 10 --out " + out.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, bad.string() + ": error: /entities/0/polygon/vertices: entity 0 (\"wedge\"): the vertices run "
                                    "clockwise; list them counter-clockwise (reverse the list)\n");
    EXPECT_EQ(readFile(out), "untouched");
    // The shipped polygon level runs.
    EXPECT_EQ(stepwise("run " + level("polygons.json") + " --steps 30").exitCode, 0);
}

// With no display the window must not start: Debian's SDL falls back to an
// invisible "offscreen" driver, where the editor would run unseen until
// killed. `timeout` turns such a hang into exit code 124.
TEST_F(Cli, EditWithNoDisplaySaysSoAndExitsOne) {
    const fs::path err = dir_ / "stderr.txt";
    const std::string command = "env -u DISPLAY -u WAYLAND_DISPLAY -u SDL_VIDEODRIVER timeout 60 " +
                                std::string(STEPWISE_BINARY) + " edit " + level("orbit.json") + " --config " +
                                (dir_ / "cfg").string() + " >/dev/null 2>" + err.string() + " </dev/null";
    const int status = std::system(command.c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 1);
    EXPECT_NE(readFile(err).find("stepwise: error: cannot start SDL video (is there a display? use "
                                 "--script/--screenshot for headless runs)"),
              std::string::npos)
        << readFile(err);
}

// ---- outputs ---------------------------------------------------------

// `--out missing/o.json --trace t.csv --contacts c.jsonl` fails on --out
// before the first step, with exit 2, and writes neither t.csv nor c.jsonl
// (not the whole simulation first, and then fail).
TEST_F(Cli, EveryOutputIsCheckedBeforeSteppingAndNothingIsWrittenOnExitTwo) {
    const fs::path file = write("forces.json", kForces), trace = dir_ / "t.csv", contacts = dir_ / "c.jsonl";
    Outcome o = stepwise("run " + file.string() + " --steps 5 --out " + (dir_ / "missing" / "o.json").string() +
                         " --trace " + trace.string() + " --contacts " + contacts.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, (dir_ / "missing" / "o.json").string() + ": error: cannot write: No such file or directory\n");
    EXPECT_FALSE(fs::exists(trace));
    EXPECT_FALSE(fs::exists(contacts));
    // The trace's folder is the bad one: same, and no temporary is left.
    o = stepwise("run " + file.string() + " --steps 5 --out " + (dir_ / "o.json").string() + " --trace " +
                 (dir_ / "nope" / "t.csv").string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_FALSE(fs::exists(dir_ / "o.json"));
    for (const auto& entry : fs::directory_iterator(dir_))
        EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
}

// A diverging run exits 3 and writes nothing at all: no trace, no
// contacts, as its "no output written" says.
TEST_F(Cli, ADivergedRunWritesNoOutputAtAll) {
    const fs::path file = write("stiff.json", R"({"world": {"gravity": {"x": 0, "y": 0}, "dt": 0.1, "integrator": "explicit_euler"},
      "entities": [{"name": "bob", "position": {"x": 1.5, "y": 0}},
                   {"name": "s", "spring": {"a": "bob", "anchor": {"x": 0, "y": 0}, "k": 1e6, "rest_length": 1}}]})");
    const fs::path out = dir_ / "o.json", trace = dir_ / "t.csv", contacts = dir_ / "c.jsonl";
    Outcome o = stepwise("run " + file.string() + " --steps 10000 --out " + out.string() + " --trace " +
                         trace.string() + " --contacts " + contacts.string());
    EXPECT_EQ(o.exitCode, 3) << o.err;
    EXPECT_NE(o.err.find("; --out, --trace, --contacts not written\n"), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_FALSE(fs::exists(trace));
    EXPECT_FALSE(fs::exists(contacts));
    EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1) << "only the level";
}

// `--trace L.json` on a diverging level replaced the level with the CSV.
// No output may be an input, and no two outputs one file: compared by
// identity, not spelling.
TEST_F(Cli, AnOutputThatIsTheInputOrAnotherOutputIsRefusedBeforeStepping) {
    const std::string text = R"({"world": {"gravity": {"x": 0, "y": 0}, "dt": 0.1, "integrator": "explicit_euler"},
      "entities": [{"name": "bob", "position": {"x": 1.5, "y": 0}},
                   {"name": "s", "spring": {"a": "bob", "anchor": {"x": 0, "y": 0}, "k": 1e6, "rest_length": 1}}]})";
    const fs::path file = write("L.json", text);
    fs::create_hard_link(file, dir_ / "link.json");
    const std::string dotted = (dir_ / "." / "L.json").string();
    struct Case {
        std::string args, message;
    };
    const std::vector<Case> cases = {
        {"--trace " + file.string(), "stepwise: error: --trace: " + file.string() + " is the input " + file.string() +
                                         "; refusing to replace it (give the output another name)\n"},
        {"--out " + dotted, "stepwise: error: --out: " + dotted + " is the input " + file.string() +
                                "; refusing to replace it (give the output another name)\n"},
        {"--contacts " + (dir_ / "link.json").string(),
         "stepwise: error: --contacts: " + (dir_ / "link.json").string() + " is the input " + file.string() +
             "; refusing to replace it (give the output another name)\n"},
        {"--trace " + (dir_ / "t.csv").string() + " --contacts " + (dir_ / "." / "t.csv").string(),
         "stepwise: error: --contacts: " + (dir_ / "." / "t.csv").string() + " is the same file as --trace " +
             (dir_ / "t.csv").string() + "; give each output its own file\n"},
    };
    for (const Case& c : cases) {
        Outcome o = stepwise("run " + file.string() + " --steps 100 " + c.args);
        EXPECT_EQ(o.exitCode, 2) << c.args;
        EXPECT_EQ(o.err, c.message) << c.args;
        EXPECT_EQ(readFile(file), text) << c.args;
        EXPECT_FALSE(fs::exists(dir_ / "t.csv")) << c.args;
    }
    // render and edit: the same rule for their images.
    Outcome o = stepwise("render " + file.string() + " --out " + dotted);
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, "stepwise: error: --out: " + dotted + " is the input " + file.string() +
                         "; refusing to replace it (give the output another name)\n");
    EXPECT_EQ(readFile(file), text);
}

// A render sequence that diverges leaves no frames before the divergence:
// every frame waits in a temporary until the whole run succeeded.
TEST_F(Cli, ARenderSequenceThatDivergesWritesNoFrame) {
    const fs::path file = write("stiff.json", R"({"world": {"gravity": {"x": 0, "y": 0}, "dt": 0.1, "integrator": "explicit_euler"},
      "entities": [{"name": "bob", "position": {"x": 1.5, "y": 0}},
                   {"name": "s", "spring": {"a": "bob", "anchor": {"x": 0, "y": 0}, "k": 1e6, "rest_length": 1}}]})");
    Outcome o = stepwise("render " + file.string() + " --out " + (dir_ / "f.png").string() +
                         " --width 64 --height 64 --frames 3 --every 2000");
    EXPECT_EQ(o.exitCode, 3) << o.err;
    EXPECT_NE(o.err.find(" before frame 1; no frame written\n"), std::string::npos) << o.err;
    EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1) << "only the level";
}


// A read-only output (0444, as an unprivileged user) is refused and kept:
// the atomic rename needs only the folder's permission, so the file's mode
// is checked first.
TEST_F(Cli, AReadOnlyOutputIsRefusedAndKept) {
    fs::permissions(dir_, fs::perms::all);  // the folder is writable: only the file's mode refuses
    const fs::path file = write("forces.json", kForces);
    const fs::path out = write("o.json", "read-only\n");
    fs::permissions(out, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
    const fs::path errFile = dir_ / "err.txt";
    const Outcome refused = stepwiseUnprivileged("run " + file.string() + " --steps 3 --out " + out.string(), errFile);
    EXPECT_EQ(refused.exitCode, 2);
    EXPECT_EQ(refused.err, out.string() + ": error: cannot write: Permission denied\n");
    EXPECT_EQ(readFile(out), "read-only\n");
}

// `edit --screenshot` checks the file, not only its folder: a read-only
// screenshot would otherwise be replaced at the end through the rename,
// after the whole script had run. It is refused before the first frame, in
// the words of every other unwritable output, and kept.
TEST_F(Cli, EditRefusesAnUnwritableScreenshotBeforeItStarts) {
    fs::permissions(dir_, fs::perms::all);
    const fs::path file = write("forces.json", kForces);
    const fs::path png = write("shot.png", "read-only\n");
    fs::permissions(png, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
    const fs::path errFile = dir_ / "err.txt";
    const Outcome refused = stepwiseUnprivileged("edit " + file.string() + " --builtin-font --size 320x240 --screenshot " + png.string(), errFile);
    EXPECT_EQ(refused.exitCode, 2);
    EXPECT_EQ(refused.err, png.string() + ": error: cannot write: Permission denied\n");
    EXPECT_EQ(readFile(png), "read-only\n");
    const fs::path missing = dir_ / "missing" / "shot.png";
    Outcome o = stepwise("edit " + file.string() + " --builtin-font --size 320x240 --screenshot " + missing.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, missing.string() + ": error: cannot write: No such file or directory\n");
    EXPECT_FALSE(fs::exists(dir_ / "missing"));
}

// The trace is streamed, not held in memory to the end (1e6 steps make a
// 95 MB file): 100 times the steps, about the same peak.
TEST_F(Cli, TheTraceIsStreamedSoMemoryStaysFlat) {
#ifdef STEPWISE_UNDER_ASAN
    GTEST_SKIP() << "AddressSanitizer keeps freed memory in quarantine, so peak RSS says nothing about streaming; the release stage measures it";
#endif
    const fs::path file = write("forces.json", kForces);
    const long few = peakKib("run " + file.string() + " --steps 2000 --trace " + (dir_ / "a.csv").string());
    const long many = peakKib("run " + file.string() + " --steps 200000 --trace " + (dir_ / "b.csv").string());
    const auto size = fs::file_size(dir_ / "b.csv");
    EXPECT_GT(size, 30'000'000u) << "the long trace holds 200,001 rows of about 200 bytes";
    // Held in memory, the long run's peak is at least the trace's size more.
    EXPECT_LT(many - few, long(size / 1024 / 4)) << few << " KiB for 2,000 steps, " << many << " KiB for 200,000";
}

// A bad argument is blamed on the argument, not the file ("L.json: cannot
// simulate: world.dt ... got nan"), in plain words (not DBL_MAX in 309
// digits); `--dt 1e-320`, inside the documented (0, 10], is accepted; and
// `--out ""` names the option (not ": error: ...").
TEST_F(Cli, BadArgumentsNameTheArgument) {
    const fs::path file = write("forces.json", kForces);
    for (const char* dt : {"nan", "0", "-1", "inf", "11", "1e999", "abc"}) {
        Outcome o = stepwise("run " + file.string() + " --steps 1 --dt " + dt);
        EXPECT_EQ(o.exitCode, 2) << dt;
        EXPECT_EQ(o.err.substr(0, o.err.find('\n')),
                  std::string("--dt: expected seconds per step, a number in (0, 10], got \"") + dt + "\"")
            << dt;
    }
    Outcome o = stepwise("run " + file.string() + " --steps 2 --dt 1e-320");
    EXPECT_EQ(o.exitCode, 0) << o.err;
    EXPECT_NE(o.out.find("ran 2 steps of 9.9998886718268301e-321 s"), std::string::npos) << o.out;
    for (const char* option : {"--out", "--trace", "--contacts"}) {
        o = stepwise("run " + file.string() + " --steps 1 " + option + " ''");
        EXPECT_EQ(o.exitCode, 2) << option;
        EXPECT_EQ(o.err.substr(0, o.err.find('\n')), std::string(option) + ": expected a file name, got \"\"");
    }
    o = stepwise("render " + file.string() + " --out ''");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err.substr(0, o.err.find('\n')), "--out: expected a file name, got \"\"");
}

// `--steps 1000000000000000000` must not run silently until killed. A trace
// that cannot fit on the disk is refused up front; a long run says how long
// it will take; Ctrl-C stops it and writes nothing.
TEST_F(Cli, AnEndlessRunIsBoundedEstimatedAndInterruptible) {
    const fs::path file = write("forces.json", kForces);
    Outcome o = stepwise("run " + file.string() + " --steps 1000000000000000000 --trace " + (dir_ / "t.csv").string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err.rfind("stepwise: error: --trace: 1000000000000000000 steps need at least 2.6e+19 bytes (26 a "
                          "step); the disk holding " + (dir_ / "t.csv").string() + " has ", 0),
              0u)
        << o.err;
    EXPECT_FALSE(fs::exists(dir_ / "t.csv"));
    // Interrupted after 3 s (Ctrl-C sends SIGINT): the estimate was printed
    // after 1 s.
    const fs::path errFile = dir_ / "err.txt";
    const pid_t child = ::fork();
    if (child == 0) {
        const std::string command = "exec " + std::string(STEPWISE_BINARY) + " run " + file.string() +
                                    " --steps 1000000000000000000 --out " + (dir_ / "o.json").string() +
                                    " >/dev/null 2>" + errFile.string() + " </dev/null";
        ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    ::sleep(3);
    ::kill(child, SIGINT);
    int status = 0;
    ::waitpid(child, &status, 0);
    o.err = readFile(errFile);
    EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 130) << o.err;
    EXPECT_NE(o.err.find("stepwise: note: " + file.string() + ": 1000000000000000000 steps at "), std::string::npos)
        << o.err;
    EXPECT_NE(o.err.find(" years; Ctrl-C stops the run and writes nothing\n"), std::string::npos) << o.err;
    EXPECT_NE(o.err.find(" of 1000000000000000000; --out not written\n"), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(dir_ / "o.json"));
}

/// Starts `stepwise ARGS` with stderr to `errFile`; SIGINT ignored in the
/// child when `ignoreInterrupt` (as a shell's background job has it).
pid_t startStepwise(const std::vector<std::string>& args, const fs::path& errFile, bool ignoreInterrupt) {
    const pid_t child = ::fork();
    if (child == 0) {
        if (ignoreInterrupt) ::signal(SIGINT, SIG_IGN);
        const int err = ::open(errFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        ::dup2(err, 2);
        const int null = ::open("/dev/null", O_RDWR);
        ::dup2(null, 0);
        ::dup2(null, 1);
        std::vector<char*> argv{const_cast<char*>(STEPWISE_BINARY)};
        for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        ::execv(STEPWISE_BINARY, argv.data());
        _exit(127);
    }
    return child;
}

// An interrupt outside the step loop (here while `render --frames` has its
// frames in hidden temporaries, put in place together at the end) exits 130
// at once: no temporary is left, and any frame on disk is complete. SIGTERM
// is taken the same way.
TEST_F(Cli, AnInterruptWhileWritingFramesExits130AndLeavesNoTemporary) {
    for (const int signal : {SIGINT, SIGTERM}) {
        SCOPED_TRACE(signal == SIGINT ? "SIGINT" : "SIGTERM");
        const fs::path frames = dir_ / ("frames" + std::to_string(signal));
        fs::create_directory(frames);
        const fs::path errFile = dir_ / "err.txt";
        const pid_t child = startStepwise({"render", level("pile.json"), "--out", (frames / "f.png").string(), "--frames",
                                           "2000", "--every", "1", "--width", "64", "--height", "48"},
                                          errFile, false);
        // Wait for a hundred frames' temporaries (OSMesa starts in well under
        // 20 s): more than a fixed table of them would hold.
        std::ptrdiff_t pending = 0;
        for (int i = 0; i < 400 && pending < 100; ++i) {
            ::usleep(50'000);
            pending = std::distance(fs::directory_iterator(frames), fs::directory_iterator());
        }
        EXPECT_GE(pending, 100);
        ::kill(child, signal);
        int status = 0;
        ::waitpid(child, &status, 0);
        EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 130) << readFile(errFile);
        EXPECT_EQ(readFile(errFile), "stepwise: error: interrupted; every output is as it was or complete\n");
        std::size_t complete = 0;
        for (const auto& entry : fs::directory_iterator(frames)) {
            const std::string name = entry.path().filename().string();
            EXPECT_EQ(name.find(".tmp-"), std::string::npos) << name << " left behind";
            const std::string bytes = readFile(entry.path());
            ASSERT_GE(bytes.size(), 12u) << name;
            EXPECT_EQ(bytes.substr(bytes.size() - 8), std::string("IEND\xae\x42\x60\x82", 8)) << name << " is cut short";
            ++complete;
        }
        EXPECT_EQ(complete, 0u) << "frames go in place only when all are drawn";
    }
}

// The most frames render takes (100,000) are checked as outputs, each
// against the others, before any work: by identity in a map, which takes
// well under a second, where comparing each with every one before took
// minutes. The run then stops at a later refusal, having written nothing.
TEST_F(Cli, A100000FrameRenderChecksItsOutputsBeforeAnyWork) {
    const fs::path frames = dir_ / "many";
    fs::create_directory(frames);
    const Outcome o = stepwise("render " + level("orbit.json") + " --out " + (frames / "f.png").string() +
                               " --frames 100000 --select nobody");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, "stepwise: error: --select: " + level("orbit.json") + " has no entity named \"nobody\"\n");
    EXPECT_TRUE(fs::is_empty(frames));
}

// A run started with SIGINT ignored (a shell's background job) keeps
// ignoring it: it runs to the end and writes its output.
TEST_F(Cli, AnInterruptIgnoredAtStartStaysIgnored) {
    const fs::path errFile = dir_ / "err.txt", out = dir_ / "o.json";
    const pid_t child = startStepwise({"run", level("pile.json"), "--steps", "400", "--out", out.string()}, errFile, true);
    ::usleep(300'000);
    ::kill(child, SIGINT);
    int status = 0;
    ::waitpid(child, &status, 0);
    EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 0) << readFile(errFile);
    EXPECT_TRUE(fs::exists(out));
}

// On a terminal the run shows a progress line (through `script`, which
// gives the command a pseudo-terminal).
TEST_F(Cli, ALongRunShowsProgressOnATerminal) {
    const fs::path file = write("forces.json", kForces), log = dir_ / "typescript";
    const std::string command = std::string(STEPWISE_BINARY) + " run " + file.string() + " --steps 3000000";
    const int status = std::system(("timeout -s INT 4 script -qfec '" + command + "' " + log.string() +
                                    " >/dev/null 2>&1 </dev/null")
                                       .c_str());
    (void)status;
    const std::string shown = readFile(log);
    EXPECT_NE(shown.find("\rstep "), std::string::npos) << shown;
    EXPECT_NE(shown.find(" of 3000000 ("), std::string::npos) << shown;
    EXPECT_NE(shown.find(" left"), std::string::npos) << shown;
}

// ---- silent wrong answers -----------------------------------------

// implicit_euler with one spring of k >= 1e25 (m = 1) and an unconnected
// falling body: the factorisation fails, and taken anyway the step would
// keep every body where it started; up to k = 1e30, the stiffest a level
// holds, the solve is refused. The failed or inaccurate solve is refused,
// naming the bodies of its system only.
TEST_F(Cli, AnImplicitSolveThatFailsOrLosesAccuracyExitsThreeNamingItsBodies) {
    for (const char* k : {"1e25", "1e30"})
        for (const char* integrator : {"implicit_euler", "implicit_midpoint"}) {
            const fs::path file = write("stiff.json", std::string(R"({"world": {"gravity": {"x": 0, "y": -9.81}, "integrator": ")") +
                                                          integrator + R"("},
              "entities": [{"name": "a", "position": {"x": 0, "y": 0}, "mass": 1},
                           {"name": "b", "position": {"x": 1.5, "y": 0}, "mass": 1},
                           {"name": "s", "spring": {"a": "a", "b": "b", "k": )" + k + R"(, "rest_length": 1}},
                           {"name": "free", "position": {"x": 5, "y": 0}, "mass": 1}]})");
            const fs::path out = dir_ / "o.json";
            Outcome o = stepwise("run " + file.string() + " --steps 60 --out " + out.string());
            const std::string what = std::string(k) + " " + integrator;
            EXPECT_EQ(o.exitCode, 3) << what << ": " << o.out;
            EXPECT_NE(o.err.find("simulation diverged at step 1: " + std::string(integrator) + ": the linear "),
                      std::string::npos)
                << what << ": " << o.err;
            EXPECT_NE(o.err.find("; bodies of the failing system: entity 0 (\"a\"), entity 1 (\"b\"). Lower the "
                                 "stiffness or dt"),
                      std::string::npos)
                << what << ": " << o.err;
            EXPECT_EQ(o.err.find("free"), std::string::npos) << what << ": " << o.err;
            EXPECT_FALSE(fs::exists(out)) << what;
            // validate warns before the run.
            o = stepwise("validate " + file.string());
            EXPECT_EQ(o.exitCode, 0) << what;
            EXPECT_NE(o.err.find(file.string() + ": warning: spring \"s\": dt*sqrt(k/m) = "), std::string::npos)
                << what << ": " << o.err;
            EXPECT_NE(o.err.find("per substep makes " + std::string(integrator) +
                                 "'s linear system ill-conditioned (condition number about "),
                      std::string::npos)
                << what << ": " << o.err;
        }
}

// A saved impulse larger than any run of the scene can leave (here 1.6e10
// N*s: the bound is loose, since it must hold for any run a level's ranges
// allow) is dropped with a warning naming the bound, and the balls stay
// where they rest; a plausible one is kept.
TEST_F(Cli, ASavedImpulseNoRunCouldWriteIsDroppedWithAWarning) {
    const auto level = [](const char* impulse) {
        return std::string(R"({"entities": [
            {"name": "floor", "position": {"x": 0, "y": -0.5}, "static": true, "box": {"width": 10, "height": 1}},
            {"name": "a", "position": {"x": 0, "y": 0.5}, "radius": 0.5, "mass": 1},
            {"name": "b", "position": {"x": 0, "y": 1.5}, "radius": 0.5, "mass": 1}],
            "solver_state": {"contacts": [
              {"a": "floor", "b": "a", "feature": 0, "normal_impulse": )") + impulse + R"(, "tangent_impulse": 0},
              {"a": "a", "b": "b", "feature": 0, "normal_impulse": )" + impulse + R"(, "tangent_impulse": 0}]}})";
    };
    const fs::path wild = write("wild.json", level("1e11")), out = dir_ / "out.json";
    Outcome o = stepwise("run " + wild.string() + " --steps 60 --out " + out.string());
    EXPECT_EQ(o.exitCode, 0) << o.err;
    const std::string warning = ": warning: solver_state: 2 saved contact impulses up to 1e+11 N*s dropped: no "
                                "run of this scene can leave more than 16000000001.308 N*s on a contact (4 x its "
                                "dynamic mass x (2 x 1e9 m/s + g dt)); those contacts start cold, so the run does "
                                "not resume exactly\n";
    EXPECT_EQ(o.err, wild.string() + warning);
    // b, still resting on a, is where it was placed.
    const std::string saved = readFile(out);
    const std::size_t b = saved.find("\"name\": \"b\"");
    ASSERT_NE(b, std::string::npos) << saved;
    const std::size_t y = saved.find("\"y\": ", saved.find("\"position\"", b));
    EXPECT_NEAR(std::stod(saved.substr(y + 5)), 1.5, 0.01) << saved.substr(b, 200);
    o = stepwise("validate " + wild.string());
    EXPECT_NE(o.err.find(wild.string() + warning), std::string::npos) << o.err;
    const fs::path calm = write("calm.json", level("0.16"));
    o = stepwise("run " + calm.string() + " --steps 60");
    EXPECT_EQ(o.exitCode, 0);
    EXPECT_EQ(o.err.find("warning"), std::string::npos) << o.err;
}

// Values the engine cannot step (their energy, inertia or area leaves the
// doubles, or a contact's answer drowns in a speed's rounding) are refused
// when the level is read, at the field, with exit 2 and nothing written;
// docs/format.md, "Ranges".
TEST_F(Cli, InputsTheEngineCannotStepAreRefusedAtLoad) {
    const std::string floor = R"({"name": "floor", "plane": {"normal": {"x": 0, "y": 1}, "offset": 0}})";
    const struct {
        std::string entity, world, message;
    } cases[] = {
        {R"({"name": "heavy", "position": {"x": 0, "y": 0.5}, "radius": 0.5, "mass": 1e308})", "",
         "/entities/1/mass: expected a number in [1e-30, 1e+30], got 1e+308"},
        {R"({"name": "big", "position": {"x": 0, "y": 10}, "radius": 1e300})", "",
         "/entities/1/radius: expected a number in [1e-30, 1e+30], got 1e+300"},
        {R"({"name": "spinner", "position": {"x": 0, "y": 10}, "radius": 1, "angular_velocity": 1e300})", "",
         "/entities/1/angular_velocity: expected a number in [-1e+09, 1e+09], got 1e+300"},
        {R"({"name": "bullet", "position": {"x": 0, "y": 1}, "radius": 0.5, "velocity": {"x": 1e149, "y": 0}})", "",
         "/entities/1/velocity/x: expected a number in [-1e+09, 1e+09], got 1e+149"},
        {R"({"name": "slab", "position": {"x": 0, "y": 10}, "polygon": {"vertices": [{"x": -1e150, "y": 0},
             {"x": 1e150, "y": 0}, {"x": 0, "y": 1e150}]}})",
         "", "/entities/1/polygon/vertices/0/x: expected a number in [-1e+30, 1e+30], got -1e+150"},
        {R"({"name": "speck", "position": {"x": 0, "y": 10}, "polygon": {"vertices": [{"x": 0, "y": 0},
             {"x": 1e-200, "y": 0}, {"x": 0, "y": 1e-200}]}})",
         "", "/entities/1/polygon/vertices: entity 1 (\"speck\"): the polygon is 1e-200 m across; the smallest "
             "shape is 1e-30 m"},
        {R"({"name": "b", "position": {"x": 0, "y": 10}})", R"("gravity": {"x": 0, "y": -1e308})",
         "/world/gravity/y: expected a number in [-1e+30, 1e+30], got -1e+308"},
        {R"({"name": "b", "position": {"x": 0, "y": 10}})", R"("integrator": "dopri5", "adaptive_step": 1e-320)",
         "/world/adaptive_step: expected 0 (none yet) or more than 1e-12 dt (1.6666666666666667e-14 s), "
         "dopri5's smallest step, got 1e-320"},
    };
    for (const auto& c : cases) {
        const fs::path level = write("e.json", "{\"world\": {" + c.world + "}, \"entities\": [" + floor + ", " +
                                                   c.entity + "]}");
        const fs::path out = dir_ / "o.json";
        const Outcome o = stepwise("run " + level.string() + " --steps 3 --out " + out.string());
        EXPECT_EQ(o.exitCode, 2) << o.err;
        EXPECT_EQ(o.err, level.string() + ": error: " + c.message + "\n");
        EXPECT_FALSE(fs::exists(out));
    }
}

// A device or a pipe is not a level: it has no size to check against the
// limit, and reading one may never end. Refused before reading, saying what
// was expected.
TEST_F(Cli, ADeviceOrAPipeAsTheLevelIsRefusedAsNotARegularFile) {
    const fs::path fifo = dir_ / "pipe.json";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    for (const std::string path : {std::string("/dev/null"), std::string("/dev/zero"), fifo.string()}) {
        const Outcome o = stepwise("validate " + path);
        EXPECT_EQ(o.exitCode, 2) << path;
        EXPECT_EQ(o.err, path + ": error: is not a regular file (a device, pipe or socket); expected a level file\n");
    }
}

// render refuses an image past 7680 x 4320 pixels before reading the level
// (16384 x 16384 took 3.8 GB and 65 s); the largest allowed renders.
TEST_F(Cli, RenderRefusesImagesPastTheDocumentedPixelCount) {
    const fs::path out = dir_ / "big.png";
    Outcome o = stepwise("render " + level("orbit.json") + " --width 16384 --height 16384 --out " +
                         out.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, "stepwise: error: --width/--height: image size 16384x16384 is 268435456 pixels; the limit is "
                     "33177600 (7680x4320)\n");
    o = stepwise("render " + level("orbit.json") + " --width 7681 --height 4320 --out " + out.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_FALSE(fs::exists(out));
    o = stepwise("render " + level("orbit.json") + " --width 16384 --height 2025 --no-hud --out " +
                 out.string());
    EXPECT_EQ(o.exitCode, 0) << o.err;
    EXPECT_TRUE(fs::exists(out));
}

// dopri5's proposed step is saved for an exact resume. At dt > 2 s it was
// saved above 10 s, which the loader refuses; it is now capped at the frame
// (no step changes), so every dt a level may give saves a file that loads
// and resumes bit for bit.
TEST_F(Cli, Dopri5AtLongStepsSavesAnAdaptiveStepThatLoads) {
    for (const char* dt : {"0.5", "2.5", "10"}) {
        const fs::path file = write("slow.json", std::string(R"({"world": {"integrator": "dopri5", "dt": )") + dt +
                                                     R"(, "gravity": {"x": 0, "y": 0}},
            "entities": [{"name": "a", "position": {"x": 0, "y": 0}, "mass": 1, "velocity": {"x": 0.1, "y": 0}},
                         {"name": "s", "spring": {"a": "a", "anchor": {"x": 0, "y": 0}, "k": 0.01, "rest_length": 0}}]})");
        const fs::path half = dir_ / "half.json", whole = dir_ / "whole.json", resumed = dir_ / "resumed.json";
        ASSERT_EQ(stepwise("run " + file.string() + " --steps 4 --out " + half.string()).exitCode, 0) << dt;
        const Outcome loaded = stepwise("run " + half.string() + " --steps 4 --out " + resumed.string());
        ASSERT_EQ(loaded.exitCode, 0) << dt << ": " << loaded.err;
        ASSERT_EQ(stepwise("run " + file.string() + " --steps 8 --out " + whole.string()).exitCode, 0) << dt;
        EXPECT_EQ(readFile(resumed), readFile(whole)) << dt;
    }
}

// ---- the scripted editor -------------------------------------------

// `saveas missing/x.json`, `open missing.json` and `savestate missing/x.json`
// exited 0 with nothing on stderr: the failure showed only in a dialog.
TEST_F(Cli, AFailedScriptCommandStopsTheRunWithAMessage) {
    const std::string level = write("orbit.json", readFile(this->level("orbit.json"))).string();
    const std::string missing = (dir_ / "missing").string();
    struct Case {
        std::string line, message;
    };
    const std::vector<Case> cases = {
        {"saveas " + missing + "/x.json", ":2: saveas failed: Cannot save " + missing + "/x.json: " + missing +
                                              "/x.json: error: cannot write: No such file or directory\n"},
        {"open " + missing + ".json", ":2: open failed: " + missing + ".json: error: no such file\n"},
        {"savestate " + missing + "/x.json", ":2: savestate failed: Cannot save " + missing + "/x.json: " + missing +
                                                 "/x.json: error: cannot write: No such file or directory\n"},
        {"screenshot " + missing + "/x.png",
         ":2: " + missing + "/x.png: error: cannot write: No such file or directory\n"},
    };
    for (const Case& c : cases) {
        const fs::path script = write("s.txt", "fit\n" + c.line + "\nsaveas " + (dir_ / "after.json").string() + "\n");
        Outcome o = stepwise("edit " + level + " --builtin-font --size 640x400 --config " + (dir_ / "cfg").string() +
                             " --script " + script.string());
        EXPECT_EQ(o.exitCode, 2) << c.line;
        EXPECT_EQ(o.err, "stepwise: error: " + script.string() + c.message) << c.line;
        EXPECT_FALSE(fs::exists(dir_ / "after.json")) << c.line << ": the run stopped at the failed line";
    }
    // `save` of a level that has no file yet.
    const fs::path script = write("s.txt", "new\nsave\n");
    Outcome o = stepwise("edit " + level + " --builtin-font --size 640x400 --config " + (dir_ / "cfg").string() +
                         " --script " + script.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, "stepwise: error: " + script.string() + ":2: save: the level has no file yet; use saveas PATH\n");
}
