// Level files: the course notes' example, round trips, every refusal with
// its exact message, limits and atomic saves.

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world_fields.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>

#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace stepwise;
namespace fs = std::filesystem;

namespace {

using stepwise::test::readFile;

/// Parses `text`; returns the error message ("" when it loaded).
std::string refusal(const std::string& text) {
    Result<Scene> r = parseScene(text, "t.json");
    return r ? std::string() : r.error();
}

fs::path freshDir(const std::string& name) {
    fs::path dir = fs::temp_directory_path() / ("stepwise_test_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

// The two entities of the course notes (levels/course_notes.json), with straight quotes
// and wrapped in {"entities": [...]}, exactly as printed there.
const char* kCourseNotes = R"({"entities": [
  {
    "position": {
      "x": -1.7193701,
      "y": -0.09165986
    },
    "velocity": {
      "x": 0,
      "y": 0
    },
    "color": {
      "x": 0.453125,
      "y": 0.453125,
      "z": 0.453125
    },
    "type": "Water Animal"
  },
  {
    "position": {
      "x": 2.2221813,
      "y": -1.2671415
    },
    "velocity": {
      "x": 0,
      "y": 1
    },
    "radius": 0.93000000000000006,
    "color": {
      "x": 0.40625,
      "y": 0.40625,
      "z": 0.40625
    },
    "type": "Land Animal"
  }
]})";

} // namespace

TEST(SceneLoad, CourseNotesExampleLoadsWithDefaults) {
    Result<Scene> scene = parseScene(kCourseNotes, "notes.json");
    ASSERT_TRUE(scene) << scene.error();
    const Registry& r = scene->registry;
    ASSERT_EQ(r.size(), 2u);
    const Entity water = r.entities()[0], land = r.entities()[1];
    EXPECT_EQ(r.tryGet<Type>(water)->value, "Water Animal");
    EXPECT_EQ(r.tryGet<Position>(water)->value, (Vec2{-1.7193701, -0.09165986}));
    EXPECT_EQ(r.tryGet<Color>(water)->value, (Rgb{0.453125, 0.453125, 0.453125}));
    EXPECT_EQ(r.tryGet<Velocity>(land)->value, (Vec2{0.0, 1.0}));
    EXPECT_EQ(r.tryGet<Radius>(land)->value, 0.93000000000000006);
    EXPECT_FALSE(r.has<Radius>(water));
    // World defaults from the scene format (docs/format.md).
    EXPECT_EQ(scene->world.gravity, (Vec2{0.0, -9.81}));
    EXPECT_EQ(scene->world.G, 1.0);
    EXPECT_EQ(scene->world.integrator, "semi_implicit_euler");
    EXPECT_EQ(scene->world.dt, 1.0 / 60.0);
    // Not given: 0, the engine's choice at World::build (SCENE_FORMAT).
    EXPECT_EQ(scene->world.substeps, 0);
    EXPECT_EQ(scene->world.time, 0.0);
    EXPECT_EQ(scene->version, 1);
}

TEST(SceneSave, LoadSaveLoadSaveIsByteIdenticalForEveryShippedLevel) {
    int levels = 0;
    for (const auto& entry : fs::directory_iterator(fs::path(STEPWISE_SOURCE_DIR) / "levels")) {
        if (entry.path().extension() != ".json" || entry.path().filename() == "scene.schema.json") continue;
        ++levels;
        Result<Scene> first = loadSceneFile(entry.path());
        ASSERT_TRUE(first) << first.error();
        const std::string once = sceneToJsonText(*first);
        Result<Scene> second = parseScene(once, entry.path().string());
        ASSERT_TRUE(second) << second.error();
        EXPECT_EQ(sceneToJsonText(*second), once) << entry.path();
    }
    EXPECT_GE(levels, 2);
}

TEST(SceneSave, NumbersReadBackToTheIdenticalDouble) {
    Scene scene;
    const Entity e = scene.registry.create();
    const double awkward[] = {0.1, 1.0 / 3.0, 2.2221813, 0.93000000000000006, 5e-324, 9.999999999999999e29, -1e30,
                              -0.0, 123456789.123456789, 1e-7};
    for (double v : awkward) {
        scene.registry.emplace<Position>(e, Position{{v, -v}});
        Result<Scene> back = parseScene(sceneToJsonText(scene), "n.json");
        ASSERT_TRUE(back) << back.error();
        const Vec2 p = back->registry.tryGet<Position>(back->registry.entities()[0])->value;
        EXPECT_EQ(std::memcmp(&p.x, &v, sizeof v), 0) << v;
    }
}

TEST(SceneSave, LayoutIsTheContractsLayout) {
    Result<Scene> scene = parseScene(R"({"entities": [{"position": {"x": 1, "y": 2}, "name": "a", "mass": 2}]})", "l.json");
    ASSERT_TRUE(scene) << scene.error();
    EXPECT_EQ(sceneToJsonText(*scene), R"({
  "version": 1,
  "world": {
    "gravity": {"x": 0.0, "y": -9.81},
    "G": 1.0,
    "integrator": "semi_implicit_euler",
    "dt": 0.016666666666666666,
    "time": 0.0,
    "tolerance": 1e-06,
    "theta": 0.5,
    "sleep": true,
    "sleep_velocity": 0.05,
    "sleep_time": 0.5
  },
  "entities": [
    {
      "name": "a",
      "position": {"x": 1.0, "y": 2.0},
      "mass": 2.0
    }
  ]
}
)");
}

TEST(SceneLoad, SpringRestLengthDefaultsToTheLoadedDistance) {
    Result<Scene> scene = parseScene(R"({"entities": [
        {"name": "p", "position": {"x": 0, "y": 0}},
        {"name": "q", "position": {"x": 3, "y": 4}},
        {"name": "s", "spring": {"a": "p", "b": "q", "k": 10}},
        {"name": "t", "spring": {"a": "q", "anchor": {"x": 3, "y": 6}}}]})",
                                     "s.json");
    ASSERT_TRUE(scene) << scene.error();
    const auto& es = scene->registry.entities();
    EXPECT_EQ(scene->registry.tryGet<Spring>(es[2])->restLength, 5.0);
    EXPECT_EQ(scene->registry.tryGet<Spring>(es[3])->restLength, 2.0);
}

TEST(SceneLoad, PlaneNormalIsNormalisedKeepingTheHalfPlane) {
    Result<Scene> scene = parseScene(R"({"entities": [{"plane": {"normal": {"x": 0, "y": 2}, "offset": -4}}]})", "p.json");
    ASSERT_TRUE(scene) << scene.error();
    const Plane* plane = scene->registry.tryGet<Plane>(scene->registry.entities()[0]);
    EXPECT_EQ(plane->normal, (Vec2{0.0, 1.0}));
    EXPECT_EQ(plane->offset, -2.0);  // 2y >= -4  <=>  y >= -2
}

// ---- Refusals: one clear message each, asserting the exact text. ----

TEST(SceneErrors, NotJsonGivesLineAndColumn) {
    EXPECT_EQ(refusal("{\"entities\": [\n  {\"mass\": }\n]}"),
              "t.json:2:12: error: syntax error while parsing value - unexpected '}'; expected '[', '{', or a literal");
}

TEST(SceneErrors, TypographicQuotesGetTheirOwnHint) {
    EXPECT_EQ(refusal("{\"entities\": [\n  {\n    “type”: “Water Animal”\n  }]}"),
              "t.json:3:5: error: typographic quote “ where JSON needs a straight quote \"; text pasted from slides "
              "or a word processor has these. Replace every “ ” ‘ ’ with \"");
}

TEST(SceneErrors, TrailingCommaGetsItsOwnHint) {
    EXPECT_EQ(refusal("{\"entities\": [\n  {\"mass\": 1},\n]}"),
              "t.json:2:14: error: trailing comma before ']'; JSON allows no comma after the last element. Remove "
              "this comma");
    EXPECT_EQ(refusal("{\"entities\": [{\"mass\": 1, }]}"),
              "t.json:1:25: error: trailing comma before '}'; JSON allows no comma after the last element. Remove "
              "this comma");
}

TEST(SceneErrors, WrongTypeNamesThePointerExpectedAndFound) {
    EXPECT_EQ(refusal(R"({"entities": [{}, {}, {}, {"position": {"x": 0, "y": 0}, "velocity": {"x": "fast", "y": 0}}]})"),
              "t.json: error: /entities/3/velocity/x: expected a number in [-1e+09, 1e+09], got \"fast\"");
    EXPECT_EQ(refusal(R"({"entities": [{"name": 7}]})"), "t.json: error: /entities/0/name: expected a string, got 7");
    EXPECT_EQ(refusal(R"({"entities": {}})"), "t.json: error: /entities: expected an array of entities, got an empty object");
    EXPECT_EQ(refusal(R"([])"), "t.json: error: expected a level object {\"entities\": [...]}, got an empty array");
    EXPECT_EQ(refusal(R"({"world": {"dt": -1}, "entities": []})"),
              "t.json: error: /world/dt: expected a number in (0, 10], got -1");
    EXPECT_EQ(refusal(R"({"world": {"substeps": 2.5}, "entities": []})"),
              "t.json: error: /world/substeps: expected an integer in [1, 1000], got 2.5");
    EXPECT_EQ(refusal(R"({"world": {"theta": 1.5}, "entities": []})"),
              "t.json: error: /world/theta: expected a number in [0, 1], got 1.5");
    EXPECT_EQ(refusal(R"({"world": {"tolerance": 0}, "entities": []})"),
              "t.json: error: /world/tolerance: expected a number in (0, 1], got 0");
    EXPECT_EQ(refusal(R"({"world": {"adaptive_step": -1}, "entities": []})"),
              "t.json: error: /world/adaptive_step: expected a number in [0, 10], got -1");
    EXPECT_EQ(refusal(R"({"entities": [{"color": {"x": 1.5, "y": 0, "z": 0}}]})"),
              "t.json: error: /entities/0/color/x: expected a number in [0, 1], got 1.5");
    EXPECT_EQ(refusal(R"({"entities": [{"position": {"x": 1, "w": 0}}]})"),
              "t.json: error: /entities/0/position/w: unknown key \"w\" in a vector {\"x\": number, \"y\": number}");
}

TEST(SceneErrors, UnknownComponentNamesEntityAndSuggests) {
    EXPECT_EQ(refusal(R"({"entities": [{}, {"name": "ball", "position": {"x": 0, "y": 0}, "velocty": {"x": 1, "y": 0}}]})"),
              "t.json: error: /entities/1/velocty: unknown component \"velocty\" on entity 1 (\"ball\"); did you mean "
              "\"velocity\"? Known components: name, type, position, velocity, mass, static, kinematic, radius, box, polygon, "
              "capsule, chain, shapes, angle, angular_velocity, color, restitution, friction, drag, sensor, filter, plane, attractor, spring, "
              "boid, template, emitter, joint");
    EXPECT_EQ(refusal(R"({"entities": [{"box": {"width": 1, "heigth": 2}, "position": {"x": 0, "y": 0}}]})"),
              "t.json: error: /entities/0/box/heigth: unknown field \"heigth\" in \"box\"; did you mean \"height\"? "
              "Known fields: width, height");
    EXPECT_EQ(refusal(R"({"wrld": {}, "entities": []})"),
              "t.json: error: /wrld: unknown top-level key \"wrld\"; did you mean \"world\"? Known keys: version, "
              "world, view, entities, solver_state");
    EXPECT_EQ(refusal(R"({"world": {"integrator": "rk5"}, "entities": []})"),
              "t.json: error: /world/integrator: expected one of explicit_euler, semi_implicit_euler, midpoint, "
              "trapezoid, rk4, velocity_verlet, implicit_euler, implicit_midpoint, dopri5, got \"rk5\"; did you mean "
              "\"rk4\"?");
}

TEST(SceneErrors, SpringToMissingEntity) {
    EXPECT_EQ(refusal(R"({"entities": [{"name": "a", "position": {"x": 0, "y": 0}}, {"spring": {"a": "a", "b": "ghost"}}]})"),
              "t.json: error: /entities/1/spring/b: no entity is named \"ghost\" (spring on entity 1)");
    EXPECT_EQ(refusal(R"({"entities": [{"name": "a", "position": {"x": 0, "y": 0}}, {"spring": {"a": "a"}}]})"),
              "t.json: error: /entities/1/spring: expected either \"b\" (an entity name) or \"anchor\" (a point), got "
              "neither");
    EXPECT_EQ(refusal(R"({"entities": [{"spring": {"b": "x", "k": 1}}]})"),
              "t.json: error: /entities/0/spring/a: expected the name of an entity, got nothing");
}

TEST(SceneErrors, DuplicateNames) {
    EXPECT_EQ(refusal(R"({"entities": [{"name": "ball"}, {"name": "wall"}, {"name": "ball"}]})"),
              "t.json: error: /entities/2/name: duplicate name \"ball\" (also entity 0); names must be unique");
}

TEST(SceneErrors, MassRadiusAndNonFiniteNumbers) {
    EXPECT_EQ(refusal(R"({"entities": [{"position": {"x": 0, "y": 0}, "mass": 0}]})"),
              "t.json: error: /entities/0/mass: expected a number in [1e-30, 1e+30], got 0");
    EXPECT_EQ(refusal(R"({"entities": [{"position": {"x": 0, "y": 0}, "mass": -2.5}]})"),
              "t.json: error: /entities/0/mass: expected a number in [1e-30, 1e+30], got -2.5");
    EXPECT_EQ(refusal(R"({"entities": [{"position": {"x": 0, "y": 0}, "radius": -1}]})"),
              "t.json: error: /entities/0/radius: expected a number in [1e-30, 1e+30], got -1");
    EXPECT_EQ(refusal(R"({"entities": [{"position": {"x": 1e999, "y": 0}}]})"),
              "t.json:1:34: error: number 1e999 is out of double range; expected a finite number");
    // NaN is not JSON at all: the parser refuses it with a position.
    EXPECT_EQ(refusal(R"({"entities": [{"position": {"x": NaN, "y": 0}}]})"),
              "t.json:1:34: error: syntax error while parsing value - invalid literal; last read: '\"x\": N'");
}

TEST(SceneErrors, ComponentsThatNeedABody) {
    EXPECT_EQ(refusal(R"({"entities": [{"name": "ghost", "radius": 1}]})"),
              "t.json: error: /entities/0: component \"radius\" on entity 0 (\"ghost\") needs \"position\", which is "
              "missing");
    EXPECT_EQ(refusal(R"({"entities": [{"position": {"x": 0, "y": 0}, "radius": 1, "box": {"width": 1, "height": 1}}]})"),
              "t.json: error: /entities/0: an entity has at most one shape (radius, box, polygon, capsule, chain or plane), got 2");
    EXPECT_EQ(refusal(R"({"entities": [{"plane": {"normal": {"x": 0, "y": 0}}}]})"),
              "t.json: error: /entities/0/plane/normal: expected a non-zero vector, got {\"x\": 0, \"y\": 0}");
}

TEST(SceneErrors, UnsupportedVersion) {
    EXPECT_EQ(refusal(R"({"version": 2, "entities": []})"),
              "t.json: error: /version: this build reads version 1 files, got version 2");
}

TEST(SceneLimits, TooManyEntitiesIsRefusedWhileParsing) {
    LoadLimits limits;
    limits.maxEntities = 1000;
    std::string text = "{\"entities\": [";
    for (int i = 0; i < 1001; ++i) text += i ? ",{}" : "{}";
    text += "]}";
    Result<Scene> r = parseScene(text, "big.json", limits);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "big.json: error: more than 1000 entities; the limit is 1000");
    text = "{\"entities\": [";
    for (int i = 0; i < 1000; ++i) text += i ? ",{}" : "{}";
    text += "]}";
    Result<Scene> ok = parseScene(text, "big.json", limits);
    ASSERT_TRUE(ok) << ok.error();
    EXPECT_EQ(ok->registry.size(), 1000u);
}

TEST(SceneLimits, DeepNestingIsRefused) {
    std::string text = "{\"entities\": [{\"type\": " + std::string(100000, '[') + std::string(100000, ']') + "}]}";
    Result<Scene> r = parseScene(text, "deep.json");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "deep.json: error: JSON nesting deeper than 16 levels; a level file needs 4");
}

TEST(SceneLimits, OversizedFileIsRefusedBeforeReading) {
    const fs::path dir = freshDir("huge");
    const fs::path huge = dir / "huge.json";
    { std::ofstream(huge) << "{}"; }
    fs::resize_file(huge, (256ull << 20) + 1);  // sparse: costs no disk
    Result<Scene> r = loadSceneFile(huge);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), huge.string() + ": error: file is 268435457 bytes; the limit is 268435456 bytes");
    fs::remove_all(dir);
}

TEST(SceneFile, MissingFileAndDirectory) {
    EXPECT_EQ(loadSceneFile("/nonexistent/level.json").error(), "/nonexistent/level.json: error: no such file");
    EXPECT_EQ(loadSceneFile("/tmp").error(), "/tmp: error: is a directory, expected a level file");
}

TEST(SceneFile, SaveReplacesAtomicallyAndLeavesNoTemporaries) {
    const fs::path dir = freshDir("save");
    const fs::path level = dir / "level.json";
    Result<Scene> scene = parseScene(kCourseNotes, "notes.json");
    ASSERT_TRUE(scene);
    ASSERT_TRUE(saveSceneFile(*scene, level));
    const std::string first = readFile(level);
    EXPECT_EQ(first, sceneToJsonText(*scene));
    scene->world.time = 2.5;
    ASSERT_TRUE(saveSceneFile(*scene, level));
    EXPECT_NE(readFile(level), first);
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1) << "a temporary was left";
    fs::remove_all(dir);
}

TEST(SceneFile, FailedWriteLeavesTheOldFileIntact) {
    const fs::path dir = freshDir("fail");
    const fs::path level = dir / "level.json";
    const std::string old = "{\"entities\": []}\n";
    { std::ofstream(level) << old; }
    // A big scene whose write fails half-way: the child process caps its file
    // size (RLIMIT_FSIZE, which binds root too) so write() fails with EFBIG.
    Scene big;
    for (int i = 0; i < 5000; ++i) {
        const Entity e = big.registry.create();
        big.registry.emplace<Position>(e, Position{{i * 0.1, -i * 0.3}});
    }
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        std::signal(SIGXFSZ, SIG_IGN);
        rlimit limit{4096, 4096};
        ::setrlimit(RLIMIT_FSIZE, &limit);
        Result<void> saved = saveSceneFile(big, level);
        _exit(saved ? 0 : (saved.error().find("write failed: File too large") != std::string::npos ? 42 : 1));
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 42) << "the save should have failed with EFBIG";
    EXPECT_EQ(readFile(level), old);
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1) << "a temporary was left";
    fs::remove_all(dir);
}

TEST(SceneFile, SaveIntoMissingFolderFailsCleanly) {
    Scene scene;
    Result<void> r = saveSceneFile(scene, "/nonexistent-dir/level.json");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "/nonexistent-dir/level.json: error: cannot write: No such file or directory");
}

// ---- World settings table -------------------------------------------------------------

TEST(WorldFields, SchemaWorldObjectIsTheTable) {
    // The schema's world properties are the table's rows: same keys in the
    // same order, same kind, same bounds (one table, so the loader and the
    // editor's World panel cannot disagree on a range).
    const auto schema = nlohmann::json::parse(sceneJsonSchema());
    const auto& properties = schema["properties"]["world"]["properties"];
    ASSERT_EQ(properties.size(), worldFieldTable().size());
    for (const WorldFieldInfo& info : worldFieldTable()) {
        const std::string key(info.field.key);
        ASSERT_TRUE(properties.contains(key)) << key;
        const auto& p = properties[key];
        const NumberRange& r = info.field.range;
        switch (info.field.kind) {
        case FieldKind::Integer:
        case FieldKind::Number:
        case FieldKind::OptionalNumber:
            EXPECT_EQ(p["type"], info.field.kind == FieldKind::Integer ? "integer" : "number") << key;
            if (std::isfinite(r.min)) EXPECT_EQ(p[r.minExclusive ? "exclusiveMinimum" : "minimum"].get<double>(), r.min) << key;
            else EXPECT_FALSE(p.contains("minimum") || p.contains("exclusiveMinimum")) << key;
            if (std::isfinite(r.max)) EXPECT_EQ(p["maximum"].get<double>(), r.max) << key;
            else EXPECT_FALSE(p.contains("maximum")) << key;
            break;
        case FieldKind::String:
            EXPECT_EQ(p["enum"].size(), info.field.choices.size()) << key;
            break;
        default: break;
        }
    }
    EXPECT_EQ(properties["solver_iterations"]["maximum"], 1000);
    EXPECT_EQ(properties["substeps"]["minimum"], 1);
    EXPECT_EQ(properties["dt"]["exclusiveMinimum"], 0);
}

TEST(WorldFields, EveryOutOfRangeSettingIsRefusedAtItsPointer) {
    // Each numeric row's bounds, one step outside, as the loader sees them.
    for (const WorldFieldInfo& info : worldFieldTable()) {
        const NumberRange& r = info.field.range;
        if (!std::isfinite(r.max)) continue;
        const std::string key(info.field.key);
        // One past an integer bound; past 1e30, one part in a million (1e30
        // + 1 is 1e30 again).
        const double outside = r.max + std::max(1.0, r.max * 1e-6);
        // A vector's bound is each axis's.
        const bool vector = info.field.kind == FieldKind::Vector;
        const std::string value = vector ? R"({"x": )" + formatNumber(outside) + "}" : formatNumber(outside);
        const std::string text = R"({"world": {")" + key + R"(": )" + value + R"(}, "entities": []})";
        Result<Scene> scene = parseScene(text, "t.json");
        ASSERT_FALSE(scene) << key;
        EXPECT_EQ(scene.error(), "t.json: error: /world/" + key + (vector ? "/x" : "") + ": expected " +
                                     r.describe(info.field.kind == FieldKind::Integer) + ", got " +
                                     formatNumber(outside));
    }
}

TEST(WorldFields, SaveWritesGivenSettingsOnlyAndReadsThemBack) {
    Result<Scene> scene = parseScene(R"({"world": {"substeps": 7, "solver_iterations": 600, "theta": 0.25}, "entities": []})", "t.json");
    ASSERT_TRUE(scene) << scene.error();
    EXPECT_EQ(scene->world.substeps, 7);
    EXPECT_EQ(scene->world.solverIterations, 600);
    const std::string text = sceneToJsonText(*scene);
    EXPECT_NE(text.find("\"solver_iterations\": 600"), std::string::npos) << text;
    EXPECT_EQ(text.find("adaptive_step"), std::string::npos) << text;  // not given, not written
    EXPECT_EQ(text.find("restitution_threshold"), std::string::npos) << text;
    Result<Scene> again = parseScene(text, "t.json");
    ASSERT_TRUE(again) << again.error();
    EXPECT_EQ(again->world, scene->world);
}

// ---- hinge springs and breakable joints ---------------------------------

namespace {
/// Two bodies and one joint with the given members: the level the refusals
/// below edit.
std::string jointLevel(const std::string& joint) {
    return R"({"entities": [{"name": "post", "position": {"x": 0, "y": 0}, "static": true, "radius": 0.2},
        {"name": "arm", "position": {"x": 1, "y": 0}, "radius": 0.2},
        {"name": "elbow", "joint": {)" + joint + "}}]}";
}
} // namespace

TEST(SceneJoints, SpringAndMaxForceRoundTripByteForByteAndAbsentStaysAbsent) {
    for (const std::string joint :
         {std::string(R"("type": "hinge", "a": "arm", "b": "post", "spring_hz": 2.5, "spring_damping_ratio": 0.3, "max_force": 1250.75)"),
          std::string(R"("type": "hinge", "a": "arm", "b": "post", "spring_hz": 0)"),
          std::string(R"("type": "weld", "a": "arm", "b": "post", "stiffness_hz": 4, "max_force": 1e-3)"),
          std::string(R"("type": "rope", "a": "arm", "b": "post", "max_force": 1e30)")}) {
        Result<Scene> first = parseScene(jointLevel(joint), "t.json");
        ASSERT_TRUE(first) << first.error();
        const std::string once = sceneToJsonText(*first);
        Result<Scene> second = parseScene(once, "t.json");
        ASSERT_TRUE(second) << second.error();
        EXPECT_EQ(sceneToJsonText(*second), once) << joint;
        const Joint* j = second->registry.tryGet<Joint>(second->registry.entities()[2]);
        ASSERT_NE(j, nullptr);
        EXPECT_EQ(j->springHz.has_value(), joint.find("spring_hz") != std::string::npos) << joint;
        EXPECT_EQ(j->maxForce.has_value(), joint.find("max_force") != std::string::npos) << joint;
        EXPECT_EQ(once.find("spring_damping_ratio") != std::string::npos,
                  joint.find("spring_damping_ratio") != std::string::npos)
            << "absent stays absent: " << once;
    }
    Result<Scene> s = parseScene(jointLevel(R"("type": "hinge", "a": "arm", "spring_hz": 2.5, "max_force": 1250.75)"), "t.json");
    ASSERT_TRUE(s) << s.error();
    const Joint* j = s->registry.tryGet<Joint>(s->registry.entities()[2]);
    EXPECT_EQ(*j->springHz, 2.5);
    EXPECT_EQ(*j->maxForce, 1250.75);
    EXPECT_FALSE(j->springDampingRatio) << "absent: the engine's 1";
}

TEST(SceneJoints, BadSpringsMaxForcesAndWheelAxesAreRefusedAtTheirPointer) {
    const std::vector<std::pair<std::string, std::string>> cases = {
        {R"("type": "hinge", "a": "arm", "spring_hz": -1)",
         "t.json: error: /entities/2/joint/spring_hz: expected a number in [0, 1e+30], got -1"},
        {R"("type": "hinge", "a": "arm", "spring_hz": "soft")",
         "t.json: error: /entities/2/joint/spring_hz: expected a number in [0, 1e+30], got \"soft\""},
        {R"("type": "hinge", "a": "arm", "spring_damping_ratio": -0.5)",
         "t.json: error: /entities/2/joint/spring_damping_ratio: expected a number in [0, 1e+30], got -0.5"},
        {R"("type": "hinge", "a": "arm", "max_force": 0)",
         "t.json: error: /entities/2/joint/max_force: expected a number in (0, 1e+30], got 0"},
        {R"("type": "rope", "a": "arm", "max_force": -5)",
         "t.json: error: /entities/2/joint/max_force: expected a number in (0, 1e+30], got -5"},
        {R"("type": "distance", "a": "arm", "max_force": 1e31)",
         "t.json: error: /entities/2/joint/max_force: expected a number in (0, 1e+30], got 1e+31"},
        {R"("type": "hinge", "a": "arm", "max_force": null)",
         "t.json: error: /entities/2/joint/max_force: expected a number in (0, 1e+30], got null"},
        {R"("type": "wheel", "a": "arm", "axis": {"x": 0, "y": 0})",
         "t.json: error: /entities/2/joint/axis: joint on entity 2 (\"elbow\"): a wheel axis needs a non-zero length, "
         "got {\"x\": 0.0, \"y\": 0.0}"},
    };
    for (const auto& [joint, message] : cases) EXPECT_EQ(refusal(jointLevel(joint)), message) << joint;
}

TEST(SceneJoints, HingeSpringImpulseInSolverStateRoundTripsAndReachesTheSolver) {
    const std::string level = R"({"entities": [{"name": "arm", "position": {"x": 1, "y": 0}, "radius": 0.2},
        {"name": "elbow", "joint": {"type": "hinge", "a": "arm", "anchor": {"x": 0, "y": 0}, "spring_hz": 2}}],
        "solver_state": {"joints": [{"joint": "elbow", "angular_impulse": -0.125}]}})";
    Result<Scene> first = parseScene(level, "t.json");
    ASSERT_TRUE(first) << first.error();
    ASSERT_TRUE(first->solverState);
    ASSERT_EQ(first->solverState->joints.size(), 1u);
    EXPECT_EQ(first->solverState->joints[0].angular, -0.125) << "a hinge's spring travels as angular_impulse";
    const std::string once = sceneToJsonText(*first);
    EXPECT_NE(once.find(R"({"joint": "elbow", "angular_impulse": -0.125})"), std::string::npos) << once;
    // And reaches the solver: a world built from it starts the spring warm.
    Result<World> w = World::build(*first);
    ASSERT_TRUE(w) << w.error();
    ASSERT_EQ(w->solverState().joints.size(), 1u);
    EXPECT_EQ(w->solverState().joints[0].angular, -0.125);
    EXPECT_EQ(refusal(R"({"entities": [{"name": "arm", "position": {"x": 1, "y": 0}, "radius": 0.2},
        {"name": "elbow", "joint": {"type": "hinge", "a": "arm"}}],
        "solver_state": {"joints": [{"joint": "elbow", "angular_impulse": "x"}]}})"),
              "t.json: error: /solver_state/joints/0/angular_impulse: expected a finite number, got \"x\"");
}
