// The `stepwise` command line as a user meets it: exit codes, messages on
// stderr, outputs written or not written, same bytes for the same input.

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

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

TEST_F(Cli, ValidateRefusesABadFileWithExitTwoAndTheLoaderMessage) {
    const fs::path file = write("bad.json", R"({"entities": [{"name": "ball", "position": {"x": 0, "y": 0}, "mass": -1}]})");
    Outcome o = stepwise("validate " + file.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, file.string() + ": error: /entities/0/mass: expected a number > 0, got -1\n");
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

// ---- Limits and bad input everywhere (issue 7) ------------------------------

TEST_F(Cli, ValidateRefusesOneEntityPastTheDocumentedLimitAndAcceptsTheLimit) {
    // README "Limits": 1,000,000 entities. Empty entities keep the file at
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
    EXPECT_EQ(o.err, dir_.string() + ": error: cannot replace the file: Is a directory\n");
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
         "implicit_euler,implicit_midpoint}"},
        {orbit + " --out " + png.string() + " --overlay velocity,bogus",
         "stepwise: error: --overlay: unknown overlay \"bogus\"; known overlays: velocity, velocity-field, "
         "force-field, force, contacts, aabb, trails, all, none"},
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

TEST_F(Cli, BenchBadArgumentsExitTwoNamingTheArgument) {
    Outcome o = stepwise("bench");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, "stepwise: error: bench: expected a report to run: accuracy (see stepwise bench --help)\n");
    o = stepwise("bench frob");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, "stepwise: error: bench: unknown report \"frob\"; expected one of: accuracy\n");
    o = stepwise("bench accuracy --quick");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err.rfind("--out is required\n", 0), 0u) << o.err;
    o = stepwise("bench accuracy --quick --out");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err.rfind("--out: 1 required TEXT missing\n", 0), 0u) << o.err;
    o = stepwise("bench accuracy --quick --out " + (dir_ / "r").string() + " --repeat 3");
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err.rfind("The following arguments were not expected: 3 --repeat\n", 0), 0u) << o.err;
    // Checked before any measuring: fails at once and creates nothing.
    const fs::path notAFolder = write("file.txt", "");
    o = stepwise("bench accuracy --quick --out " + (notAFolder / "report").string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, "stepwise: error: --out: cannot create the folder " + (notAFolder / "report").string() +
                         ": Not a directory\n");
    o = stepwise("bench accuracy --quick --out " + notAFolder.string());
    EXPECT_EQ(o.exitCode, 2);
    EXPECT_EQ(o.err, "stepwise: error: --out: cannot create the folder " + notAFolder.string() + ": Not a directory\n");
    EXPECT_FALSE(fs::exists(dir_ / "r"));
}

TEST_F(Cli, RenderAndBenchHaveHelp) {
    for (const char* sub : {"render", "bench", "bench accuracy"}) {
        Outcome o = stepwise(std::string(sub) + " --help");
        EXPECT_EQ(o.exitCode, 0) << sub;
        EXPECT_NE(o.out.find("Usage:"), std::string::npos) << sub << ": " << o.out;
    }
}

// The scripted editor refuses a bad line at run time with the script's
// file:line and what was wrong, and exits 2 (issue 6's scripted mode;
// issue 7's "bad input everywhere").
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
