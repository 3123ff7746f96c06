// Bad input the loader must handle (from the loader fuzzer and a review of
// bad input), each as an exact-message or exact-bytes test, plus a replay of
// every file in tests/fuzz/corpus/ through the fuzzer's own property, so the
// ordinary gcc build checks them too.

#include "fuzz/pipeline_property.hpp"
#include "fuzz/scene_loader_property.hpp"

#include "stepwise/component_table.hpp"
#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"

#include "test_support.hpp"

#include <algorithm>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

using namespace stepwise;
namespace fs = std::filesystem;

namespace {

std::string refusal(std::string_view text) {
    Result<Scene> r = parseScene(text, "t.json");
    return r ? std::string() : r.error();
}

using stepwise::test::readFile;

std::string saveLoadSave(std::string_view text, std::string* first = nullptr) {
    Result<Scene> a = parseScene(text, "t.json");
    if (!a) return "refused: " + a.error();
    const std::string once = sceneToJsonText(*a);
    if (first) *first = once;
    Result<Scene> b = parseScene(once, "t.json");
    if (!b) return "saved text refused: " + b.error();
    return sceneToJsonText(*b);
}

} // namespace

// The JSON parser quotes the bytes it gave up at: a broken file's non-UTF-8
// bytes are escaped before they reach the message (and from there the
// terminal and the editor's UI).
TEST(LoaderRegressions, BytesThatAreNotUtf8AreEscapedInTheMessage) {
    EXPECT_EQ(refusal("{\"entities\": [\xff]}"),
              "t.json:1:15: error: syntax error while parsing value - invalid literal; last read: '\"entities\": "
              "[\\xFF'");
    // The parser also stops inside a valid character: its lead byte alone
    // is not UTF-8 either.
    EXPECT_EQ(refusal("{\"entities\": [é]}"),
              "t.json:1:15: error: syntax error while parsing value - invalid literal; last read: '\"entities\": "
              "[\\xC3'");
    // The fuzzer's input, kept in the corpus.
    const std::string kept = readFile(fs::path(STEPWISE_SOURCE_DIR) / "tests/fuzz/corpus/invalid-utf8-in-syntax-error.json");
    const std::string message = refusal(kept);
    EXPECT_TRUE(fuzz::isValidUtf8(message)) << message;
    EXPECT_NE(message.find("last read: '0,\\x8C'"), std::string::npos) << message;
}

// Same family: keys and values may hold control characters through JSON
// escapes; a message naming them stays on one line.
TEST(LoaderRegressions, ControlCharactersInKeysAreEscapedInTheMessage) {
    EXPECT_EQ(refusal(R"({"a\nb\u0007": 1, "entities": []})"),
              "t.json: error: /a\\x0Ab\\x07: unknown top-level key \"a\\x0Ab\\x07\". Known keys: version, world, "
              "view, entities, solver_state");
}

// A long found value is cut to 57 bytes; the cut must not split a UTF-8
// character.
TEST(LoaderRegressions, ALongFoundValueIsCutBetweenCharacters) {
    std::string value = "a";
    for (int i = 0; i < 40; ++i) value += "é";  // 2 bytes each: byte 57 is inside one
    std::string expected = "\"a";
    for (int i = 0; i < 27; ++i) expected += "é";
    EXPECT_EQ(refusal(R"({"entities": [{"position": {"x": 0, "y": 0}, "mass": ")" + value + "\"}]}"),
              "t.json: error: /entities/0/mass: expected a number in [1e-30, 1e+30], got " + expected + "...");
}

// A plane normal is normalised once: divided by its own rounded length on
// every load, {1, 2} would move in its last bit between the first and the
// second save, breaking "load, save, load, save gives identical bytes".
TEST(LoaderRegressions, APlaneNormalIsNormalisedOnceAndThenKeptBitForBit) {
    std::string first;
    const std::string second =
        saveLoadSave(R"({"entities": [{"plane": {"normal": {"x": 1, "y": 2}, "offset": 0.5}}]})", &first);
    EXPECT_EQ(second, first);
    EXPECT_NE(first.find(R"("normal": {"x": 0.4472135954999579, "y": 0.8944271909999159})"), std::string::npos) << first;
    EXPECT_NE(first.find(R"("offset": 0.22360679774997896)"), std::string::npos) << first;
}

// The largest normal a level holds is normalised exactly; past it, the
// axis is refused where it is.
TEST(LoaderRegressions, AHugePlaneNormalIsNormalisedWithoutOverflow) {
    Result<Scene> scene = parseScene(R"({"entities": [{"plane": {"normal": {"x": 1e30, "y": 1e30}, "offset": 3}}]})", "t.json");
    ASSERT_TRUE(scene) << scene.error();
    const Plane* plane = scene->registry.tryGet<Plane>(scene->registry.entities()[0]);
    const double length = std::hypot(1e30, 1e30);
    EXPECT_EQ(plane->normal, (Vec2{1e30 / length, 1e30 / length}));
    EXPECT_NEAR(plane->normal.x, 1.0 / std::sqrt(2.0), 1e-15);
    EXPECT_EQ(plane->offset, 3.0 / length);
    EXPECT_EQ(refusal(R"({"entities": [{"plane": {"normal": {"x": 1e200, "y": 1e200}, "offset": 3}}]})"),
              "t.json: error: /entities/0/plane/normal/x: expected a number in [-1e+30, 1e+30], got 1e+200");
}

// An offset that leaves the range once divided by a tiny normal's length
// would be saved as a number the loader refuses: refused here instead.
TEST(LoaderRegressions, APlaneOffsetThatOverflowsWhenNormalisedIsRefused) {
    EXPECT_EQ(refusal(R"({"entities": [{"plane": {"normal": {"x": 1e-11, "y": 0}, "offset": 1e30}}]})"),
              "t.json: error: /entities/0/plane/offset: expected an offset that stays within 1e+30 once the normal "
              "is normalised (offset / |normal|), got 1e+30 with |normal| = 1e-11");
}

// A spring without rest_length whose ends are further apart than a
// rest_length may be would be saved with one the loader refuses: refused.
TEST(LoaderRegressions, ASpringWhoseLengthOverflowsNeedsAnExplicitRestLength) {
    EXPECT_EQ(refusal(R"({"entities": [{"name": "p", "position": {"x": -1e30, "y": 0}},
                                       {"spring": {"a": "p", "anchor": {"x": 1e30, "y": 0}}}]})"),
              "t.json: error: /entities/1/spring: the ends are 2e+30 m apart, past the 1e+30 m a rest_length may "
              "be; give \"rest_length\"");
    // With one given, it loads and round-trips.
    std::string first;
    EXPECT_EQ(saveLoadSave(R"({"entities": [{"name": "p", "position": {"x": -1e30, "y": 0}},
                 {"spring": {"a": "p", "anchor": {"x": 1e30, "y": 0}, "rest_length": 1}}]})", &first),
              first);
}

// Beyond the fuzzer's 64 KiB inputs: nlohmann's parser callback rescans the
// enclosing array after every value, so refusing 1,000,001 entities through
// it takes 3 minutes (and loading a million as long). The loader is linear:
// ten times the entities must cost about ten times the time, far from the
// hundred times of a quadratic parser.
TEST(LoaderRegressions, RefusingTooManyEntitiesTakesLinearTime) {
    const auto timeToRefuse = [](std::size_t limit) {
        std::string text = "{\"entities\": [";
        text.reserve(16 + 3 * (limit + 1));
        for (std::size_t i = 0; i <= limit; ++i) text += i ? ",{}" : "{}";
        text += "]}";
        LoadLimits limits;
        limits.maxEntities = limit;
        const auto start = std::chrono::steady_clock::now();
        Result<Scene> r = parseScene(text, "t.json", limits);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        EXPECT_FALSE(r);
        if (!r) {
            EXPECT_EQ(r.error(), "t.json: error: more than " + std::to_string(limit) + " entities; the limit is " +
                                     std::to_string(limit));
        }
        return seconds;
    };
    // The fastest of three runs of each: on a shared machine a single run
    // can be descheduled for longer than the whole measurement.
    const auto fastest = [&](std::size_t limit) {
        return std::min({timeToRefuse(limit), timeToRefuse(limit), timeToRefuse(limit)});
    };
    timeToRefuse(20'000);  // warm up the allocator
    const double small = fastest(100'000);
    const double large = fastest(1'000'000);
    EXPECT_LT(large, 30.0 * small) << "100,001 entities: " << small << " s; 1,000,001: " << large << " s";
}

// The entity limit counts the objects of the top-level "entities" array
// only, not every object two levels down ("gravity" in "world" is not an
// entity).
TEST(LoaderRegressions, OnlyEntitiesCountTowardsTheEntityLimit) {
    LoadLimits limits;
    limits.maxEntities = 1;
    Result<Scene> r = parseScene(R"({"world": {"gravity": {"x": 0, "y": -1}}, "view": {"center": {"x": 0, "y": 0}},
                                     "entities": [{"position": {"x": 0, "y": 0}, "velocity": {"x": 1, "y": 0}}]})",
                                 "t.json", limits);
    ASSERT_TRUE(r) << r.error();
    r = parseScene(R"({"entities": [{}, {}]})", "t.json", limits);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.json: error: more than 1 entities; the limit is 1");
}

// docs/format.md, "Limits": nesting deeper than 16 levels is refused. Counted
// exactly (not by enclosing containers, which lets 17 pass): 16 levels reach
// the ordinary checks, 17 are refused while parsing.
TEST(LoaderRegressions, TheDepthLimitIsSixteenLevels) {
    const auto nested = [](int levels) {  // root object + entities array + entity + (levels - 3) arrays
        const int arrays = levels - 3;
        return R"({"entities": [{"type": )" + std::string(std::size_t(arrays), '[') + std::string(std::size_t(arrays), ']') +
               "}]}";
    };
    EXPECT_EQ(refusal(nested(16)), "t.json: error: /entities/0/type: expected a string, got an array");
    EXPECT_EQ(refusal(nested(17)), "t.json: error: JSON nesting deeper than 16 levels; a level file needs 4");
}

// docs/format.md, "Limits": an object holds at most 256 keys, counted while
// parsing, so the DOM's per-object key search (n^2 / 2 comparisons for n
// keys) never sees more. 256 keys reach the ordinary checks; one more is
// refused at that key, at every level of the file: the top, an entity, a
// component and the world.
TEST(LoaderRegressions, AnObjectHoldsAtMost256Keys) {
    const auto keys = [](int n, const char* prefix) {
        std::string out;
        for (int i = 0; i < n; ++i) out += (i ? ", \"" : "\"") + std::string(prefix) + std::to_string(i) + "\": 1";
        return out;
    };
    const std::string limit = "more than 256 keys in one object; the limit is 256 (a level's objects have about 20)";
    // 256 keys: past the reader, refused for what they are.
    EXPECT_EQ(refusal("{" + keys(255, "k") + R"(, "entities": []})"),
              "t.json: error: /k0: unknown top-level key \"k0\". Known keys: version, world, view, entities, solver_state");
    const std::string top = "{" + keys(257, "k") + "}";
    EXPECT_EQ(refusal(top), "t.json:1:" + std::to_string(top.find("\"k256\"") + 1) + ": error: " + limit);
    const std::string entity = R"({"entities": [{)" + keys(257, "c") + "}]}";
    EXPECT_EQ(refusal(entity),
              "t.json:1:" + std::to_string(entity.find("\"c256\"") + 1) + ": error: /entities/0: " + limit);
    const std::string component = R"({"entities": [{"position": {)" + keys(257, "f") + "}}]}";
    EXPECT_EQ(refusal(component), "t.json:1:" + std::to_string(component.find("\"f256\"") + 1) +
                                      ": error: /entities/0/position: " + limit);
    const std::string world = R"({"world": {)" + keys(257, "w") + R"(}, "entities": []})";
    EXPECT_EQ(refusal(world), "t.json:1:" + std::to_string(world.find("\"w256\"") + 1) + ": error: /world: " + limit);
    // The limit is a setting: raised, the same file is past the reader.
    LoadLimits wide;
    wide.maxKeysPerObject = 1000;
    Result<Scene> r = parseScene(top, "t.json", wide);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().find(limit), std::string::npos) << r.error();
}

// Saved contact impulses can only be what a run writes: a normal impulse
// that pushes (>= 0), between two entities, one entry per pair and feature
// (in either order). Anything else would change the physics on resume.
TEST(LoaderRegressions, SavedContactsAreOnlyWhatARunWrites) {
    const auto level = [](const std::string& contacts) {
        return R"({"entities": [{"name": "a", "position": {"x": 0, "y": 0.5}, "radius": 0.5},
                                {"name": "b", "position": {"x": 0, "y": 1.5}, "radius": 0.5}],
                   "solver_state": {"contacts": [)" + contacts + "]}}";
    };
    const std::string good = R"({"a": "a", "b": "b", "feature": 0, "normal_impulse": 0.1, "tangent_impulse": 0})";
    ASSERT_TRUE(parseScene(level(good), "t.json"));
    EXPECT_EQ(refusal(level(R"({"a": "a", "b": "b", "feature": 0, "normal_impulse": -100, "tangent_impulse": 0})")),
              "t.json: error: /solver_state/contacts/0/normal_impulse: expected a number >= 0, got -100");
    EXPECT_EQ(refusal(level(R"({"a": "a", "b": "a", "feature": 0, "normal_impulse": 1, "tangent_impulse": 0})")),
              "t.json: error: /solver_state/contacts/0/b: a contact joins an entity to itself");
    const std::string duplicate =
        "t.json: error: /solver_state/contacts/1: this pair and feature have an entry already (/solver_state/contacts/0)";
    EXPECT_EQ(refusal(level(good + ", " + good)), duplicate);
    EXPECT_EQ(refusal(level(good + R"(, {"a": "b", "b": "a", "feature": 0, "normal_impulse": 1, "tangent_impulse": 0})")),
              duplicate);
    // Another feature of the same pair is another contact point.
    EXPECT_TRUE(parseScene(level(good + R"(, {"a": "a", "b": "b", "feature": 1, "normal_impulse": 1, "tangent_impulse": 0})"),
                           "t.json"));
}

// Every kept input (findings and hand-written edge cases) satisfies the
// fuzzers' properties: refused with one line of UTF-8 naming the file, or
// loads and round-trips to identical bytes; and steps, or stops with a
// message, and saves what loads.
TEST(LoaderRegressions, EveryFileInTheFuzzCorpusSatisfiesTheFuzzersProperty) {
    int files = 0;
    for (const auto& entry : fs::directory_iterator(fs::path(STEPWISE_SOURCE_DIR) / "tests" / "fuzz" / "corpus")) {
        ++files;
        EXPECT_EQ(fuzz::checkLoaderProperty(readFile(entry.path())), "") << entry.path();
        EXPECT_EQ(fuzz::checkPipelineProperty(readFile(entry.path())), "") << entry.path();
    }
    EXPECT_GE(files, 6);
}

// ---- the JSON itself -----------------------------------------------

// Duplicate keys: nlohmann keeps the last one, so a level with "mass" twice
// would load with the second. Refused, naming the second by its JSON
// Pointer and place, and the first by its place.
TEST(LoaderRegressions, DuplicateKeysAreRefusedWithThePointerOfTheSecond) {
    EXPECT_EQ(refusal(R"({"entities": [{"name": "a", "mass": 1, "mass": 2}]})"),
              "t.json:1:40: error: /entities/0/mass: duplicate key \"mass\" (first at line 1, column 29); a key "
              "may appear once in an object");
    EXPECT_EQ(refusal("{\"entities\": [],\n \"entities\": [{}]}"),
              "t.json:2:2: error: /entities: duplicate key \"entities\" (first at line 1, column 2); a key may "
              "appear once in an object");
    EXPECT_EQ(refusal(R"({"world": {"dt": 0.01, "dt": 0.02}, "entities": []})"),
              "t.json:1:24: error: /world/dt: duplicate key \"dt\" (first at line 1, column 12); a key may appear "
              "once in an object");
    // Spelled differently, the same key: "m\u0061ss" is "mass".
    EXPECT_EQ(refusal(R"({"entities": [{"mass": 1, "m\u0061ss": 2}]})"),
              "t.json:1:27: error: /entities/0/mass: duplicate key \"mass\" (first at line 1, column 16); a key "
              "may appear once in an object");
    // Past 16 keys the keys seen are kept in a hash map: same answer.
    std::string many = R"({"entities": [{"velocity": {)";
    for (int i = 0; i < 40; ++i) many += "\"k" + std::to_string(i) + "\": 0, ";
    many += R"("k7": 1}}]})";
    const std::string r = refusal(many);
    EXPECT_NE(r.find("error: /entities/0/velocity/k7: duplicate key \"k7\""), std::string::npos) << r;
    // A key with an escaped quote and slash is found and named by pointer.
    EXPECT_EQ(refusal(R"({"entities": [{"a/\"b": 1, "a/\"b": 2}]})"),
              "t.json:1:28: error: /entities/0/a~1\"b: duplicate key \"a/\"b\" (first at line 1, column 16); a key "
              "may appear once in an object");
    // The same key in different objects is fine.
    EXPECT_EQ(refusal(R"({"entities": [{"name": "a", "position": {"x": 0, "y": 0}}, {"name": "b", "position": {"x": 1, "y": 0}}]})"),
              "");
}

// nlohmann's lexer takes a NUL byte for the end of the input, so a level
// followed by a NUL and anything at all would load: refused.
TEST(LoaderRegressions, ANulByteAnywhereIsRefused) {
    const std::string level = "{\"entities\": []}\n";
    EXPECT_EQ(refusal(level + std::string(1, '\0') + "garbage"),
              "t.json:2:1: error: a NUL byte; a level file is text and has none (a file cut short or padded by a "
              "crash often ends in NUL bytes)");
    EXPECT_EQ(refusal(level + std::string(1, '\0')).substr(0, 27), "t.json:2:1: error: a NUL by");
    EXPECT_EQ(refusal(std::string("{\"entities\": [{\"name\": \"a") + '\0' + "\"}]}").substr(0, 30),
              "t.json:1:26: error: a NUL byte");
}

// Counting only the objects directly in "entities" would let every other
// shape build its whole DOM first (60 MB of [[{}, {}, ...]]: 23 s and
// 1.5 GB). Every value counts, in the file and in one entity.
TEST(LoaderRegressions, EveryJsonValueCountsTowardsTheLimits) {
    LoadLimits limits;
    limits.maxValues = 100;
    std::string numbers = "[";
    for (int i = 0; i < 200; ++i) numbers += i ? ",0" : "0";
    numbers += "]";
    const std::string text = R"({"entities": [{"name": "a", "tag": )" + numbers + "}]}";
    Result<Scene> r = parseScene(text, "t.json", limits);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.json:1:227: error: more than 100 JSON values (numbers, strings, objects, arrays); the "
                         "limit is 100 (a level uses about 14 per entity)");
    // Nested objects count as well as their members.
    std::string nested = R"({"entities": [{"name": )";
    for (int i = 0; i < 120; ++i) nested += "{\"a\": ";
    nested += "1";
    for (int i = 0; i < 120; ++i) nested += "}";
    nested += "}]}";
    limits.maxDepth = 200;
    r = parseScene(nested, "t.json", limits);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find("more than 100 JSON values"), std::string::npos) << r.error();
    // One entity: at most maxValuesPerEntity.
    limits = LoadLimits{};
    limits.maxValuesPerEntity = 50;
    r = parseScene(text, "t.json", limits);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.json:1:131: error: /entities/0: more than 50 JSON values in one entity; the limit is 50");
    // "world" and "view" hold a few settings: 10,000 values at most.
    std::string gravity = R"({"entities": [], "world": {"gravity": [)";
    for (int i = 0; i < 20000; ++i) gravity += i ? ",0" : "0";
    r = parseScene(gravity + "]}}", "t.json");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.json:1:20038: error: /world: more than 10000 JSON values; this section holds a few settings");
    // A real entity is far below it.
    EXPECT_EQ(refusal(R"({"entities": [{"name": "a", "position": {"x": 0, "y": 0}, "velocity": {"x": 0, "y": 0},
                          "mass": 1, "radius": 0.5, "color": {"x": 1, "y": 0, "z": 0}}]})"),
              "");
}

// Wrong shapes that hold many values are refused at their first child, with
// the message the component layer gives for them, before any DOM is built.
TEST(LoaderRegressions, ArraysWhereObjectsBelongAreRefusedAtTheirFirstChild) {
    LoadLimits limits;
    limits.maxValues = 10;  // far fewer than these files hold: refused before the count is reached
    std::string list;
    for (int i = 0; i < 50; ++i) list += i ? ", {}" : "{}";
    Result<Scene> r = parseScene(R"({"entities": [{}, [)" + list + "]]}", "t.json", limits);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.json: error: /entities/1: expected an entity object {\"component\": value, ...}, got an array");
    r = parseScene("[" + list + "]", "t.json", limits);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.json: error: expected a level object {\"entities\": [...]}, got an array");
    r = parseScene(R"({"entities": {"a": )" + std::string("[") + list + "]}}", "t.json", limits);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.json: error: /entities: expected an array of entities, got an object");
    // Empty ones still get the component layer's "empty" wording.
    EXPECT_EQ(refusal(R"({"entities": [[]]})"),
              "t.json: error: /entities/0: expected an entity object {\"component\": value, ...}, got an empty array");
}

// A 10 MB unknown component name would give a 20 MB one-line message (the
// name twice: in the pointer and quoted), and the "did you mean" search
// would take seconds on it. Long runs are cut in every loader message.
TEST(LoaderRegressions, LongNamesAreCutInMessages) {
    const std::string name(10u << 20, 'q');
    const std::string r = refusal(R"({"entities": [{")" + name + R"(": 1}]})");
    EXPECT_LT(r.size(), 1000u);
    EXPECT_EQ(r.rfind("t.json: error: /entities/0/" + std::string(60, 'q') + "...(10485760 bytes): unknown component \"" +
                          std::string(60, 'q') + "...(10485760 bytes)\" on entity 0",
                      0),
              0u)
        << r;
    EXPECT_NE(r.find("unknown component \"qqqqq"), std::string::npos) << r;
    // A long entity name in a relation message, and a long string value.
    const std::string longName(5000, 'n');
    const std::string twice = refusal(R"({"entities": [{"name": ")" + longName + R"("}, {"name": ")" + longName + R"("}]})");
    EXPECT_LT(twice.size(), 400u) << twice;
    EXPECT_NE(twice.find("duplicate name \"nnnn"), std::string::npos) << twice;
    EXPECT_NE(twice.find("...(5000 bytes)"), std::string::npos) << twice;
    // Multi-byte characters are never split.
    std::string accents;
    for (int i = 0; i < 200; ++i) accents += "é";
    const std::string cut = refusal(R"({"entities": [{")" + accents + R"(": 1}]})");
    EXPECT_TRUE(fuzz::isValidUtf8(cut)) << cut;
    EXPECT_NE(cut.find("...(400 bytes)"), std::string::npos) << cut;
}

// A key of many short runs joined by form feeds and newlines (from a fuzz
// run): cut to 4,096 bytes and then escaped as \xNN, its message would be
// 4,977 bytes long. Escaped first and cut after, the bound holds for any
// key.
TEST(LoaderRegressions, EscapingControlCharactersDoesNotPushAMessagePastTheBound) {
    // Short runs (40 bytes, 100 once escaped: under the 120 that gets a run
    // cut on its own) separated by spaces, so only the whole-message bound
    // applies.
    std::string key;
    for (int run = 0; run < 200; ++run) {
        for (int i = 0; i < 20; ++i) key += "k\\f";  // JSON escape: a form feed
        key += ' ';
    }
    const std::string r = refusal(R"({"entities": [{")" + key + R"(": 1}]})");
    EXPECT_LE(r.size(), 4096u + 64u) << r.size();
    EXPECT_NE(r.find("k\\x0Ck\\x0C"), std::string::npos) << r.substr(0, 200);
    EXPECT_NE(r.find("...(message cut: "), std::string::npos) << r.substr(r.size() - 100);
    // The fuzzer's input, kept in the corpus (the corpus test replays the
    // property on it as well).
    const std::string kept =
        readFile(fs::path(STEPWISE_SOURCE_DIR) / "tests/fuzz/corpus/long-key-of-control-characters.json");
    const std::string message = refusal(kept);
    EXPECT_LE(message.size(), 4096u + 64u) << message.size();
}

// ---- ranges the engine can step (docs/format.md, "Ranges") ------------

namespace {

std::string number(double v) { return formatNumber(v); }

} // namespace

// Every bound at once: the lightest, heaviest, smallest and largest body of
// each shape, still or at the fastest speed and spin, under no gravity or
// the strongest, on a floor beside a wall, under every integrator. Each
// loads; it is refused when built if no first step could take it, or builds
// and takes 3 steps, or stops saying which body left which
// range; nothing becomes inf or NaN; and what a run that did not stop saves
// loads again.
TEST(LoaderRegressions, ExtremeLevelsStepWithFiniteNumbersAndSaveWhatLoads) {
    int ran = 0, stopped = 0, refused = 0;
    for (const char* integrator : {"explicit_euler", "semi_implicit_euler", "midpoint", "rk4", "velocity_verlet",
                                   "implicit_euler", "implicit_midpoint", "dopri5"})
        for (const double mass : {1e-30, 1.0, 1e30})
            for (const double size : {1e-30, 1.0, 1e30})
                for (const double speed : {0.0, 1e9})
                    for (const double spin : {0.0, -1e9})
                        for (const double gravity : {0.0, 1e30})
                            for (const char* shape : {"radius", "box", "polygon"}) {
                                const std::string s = number(size), m = number(-size);
                                const std::string geometry =
                                    std::string(shape) == "radius" ? R"("radius": )" + s
                                    : std::string(shape) == "box"
                                        ? R"("box": {"width": )" + s + R"(, "height": )" + s + "}"
                                        : R"("polygon": {"vertices": [{"x": )" + m + R"(, "y": )" + m +
                                              R"(}, {"x": )" + s + R"(, "y": )" + m + R"(}, {"x": 0, "y": )" + s +
                                              "}]}";
                                const std::string text =
                                    R"({"world": {"integrator": ")" + std::string(integrator) +
                                    R"(", "gravity": {"x": 0, "y": )" + number(-gravity) + R"(}}, "entities": [
                                    {"name": "floor", "position": {"x": 0, "y": -0.5}, "static": true,
                                     "box": {"width": 40, "height": 1}},
                                    {"name": "wall", "plane": {"normal": {"x": -1, "y": 0}, "offset": -3}},
                                    {"name": "b", "position": {"x": 0, "y": )" + s + R"(}, "mass": )" +
                                    number(mass) + R"(, "velocity": {"x": )" + number(speed) + R"(, "y": )" +
                                    number(-speed) + R"(}, "angular_velocity": )" + number(spin) + ", " + geometry +
                                    "}]}";
                                const std::string what = text;
                                Result<Scene> scene = parseScene(text, "extreme.json");
                                ASSERT_TRUE(scene) << scene.error() << "\n" << what;
                                Result<World> world = World::build(*scene);
                                if (!world) {
                                    // Gravity or a spin no first step could take (past 1e9 m/s
                                    // in one step): refused when built, naming the value.
                                    ++refused;
                                    EXPECT_NE(world.error().find(", past the 1e+09 m/s a run holds"),
                                              std::string::npos)
                                        << world.error() << "\n" << what;
                                    EXPECT_TRUE(gravity > 0.0 || spin != 0.0) << world.error() << "\n" << what;
                                    continue;
                                }
                                bool ok = true;
                                for (int step = 0; step < 3 && ok; ++step) {
                                    const Result<void> r = world->step();
                                    if (r) continue;
                                    ok = false;
                                    ++stopped;
                                    EXPECT_NE(r.error().find(", beyond the +-"), std::string::npos)
                                        << r.error() << "\n" << what;
                                }
                                if (!ok) continue;
                                ++ran;
                                const std::string saved = test::savedRunText(*world, *scene);
                                Result<Scene> again = parseScene(saved, "saved.json");
                                EXPECT_TRUE(again) << again.error() << "\n" << saved;
                            }
    // Every outcome is exercised: gravity of 1e30 and huge spinning shapes
    // are refused, tiny bodies hit at 1e9 m/s spin past 1e9 rad/s, and the
    // rest run on.
    EXPECT_GT(refused, 1000);
    EXPECT_GT(ran, 500);
    EXPECT_GT(stopped, 100);
}

// A ball fired at a wall stops at the wall, at every speed a level holds:
// a contact's answer is a difference of speeds, and past 1e9 m/s it drowned
// in the speed's rounding (at 1e20 the ball stopped where it started).
TEST(LoaderRegressions, ABallFiredAtAWallStopsAtTheWallAtEverySpeed) {
    for (const char* wall : {R"({"name": "wall", "plane": {"normal": {"x": -1, "y": 0}, "offset": -3}})",
                             R"({"name": "wall", "position": {"x": 3.5, "y": 0}, "static": true,
                                 "box": {"width": 1, "height": 10}})"})
        for (const double dt : {1.0 / 60.0, 1.0 / 240.0})
            for (double speed = 1e2; speed <= 1e9; speed *= 10.0) {
                const std::string text = R"({"world": {"gravity": {"x": 0, "y": 0}, "dt": )" + number(dt) +
                                         R"(}, "entities": [{"name": "ball", "position": {"x": 0, "y": 0},
                                         "radius": 0.5, "velocity": {"x": )" + number(speed) + R"(, "y": 0}}, )" +
                                         wall + "]}";
                Result<Scene> scene = parseScene(text, "wall.json");
                ASSERT_TRUE(scene) << scene.error();
                Result<World> built = World::build(*scene);
                ASSERT_TRUE(built) << built.error();
                World& world = *built;
                // Enough steps to cover the 2 m gap, and two more at rest.
                const int steps = 2 + int(std::ceil(2.0 / (speed * dt)));
                for (int step = 0; step < steps; ++step) ASSERT_TRUE(world.step().ok()) << speed;
                EXPECT_NEAR(world.bodyPosition(0).x, 2.5, 1e-6) << speed << " m/s, dt " << dt << ", " << wall;
                EXPECT_NEAR(world.bodyVelocity(0).x, 0.0, 1e-6) << speed << " m/s, dt " << dt;
            }
}
