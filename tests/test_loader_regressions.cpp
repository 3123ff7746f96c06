// Findings of the loader fuzzer and of a review of bad input, each
// kept as an exact-message or exact-bytes test, plus a replay of every file
// in tests/fuzz/corpus/ through the fuzzer's own property, so the findings stay
// fixed in the ordinary gcc build too.

#include "fuzz/scene_loader_property.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"

#include "test_support.hpp"

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

// Fuzzer finding 1 (first minute): the JSON parser quotes the bytes it gave
// up at, so a broken file's non-UTF-8 bytes went straight into the message
// (and from there into the terminal and the editor's UI).
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
              "t.json: error: /a\\x0Ab\\x07: unknown top-level key \"a\\x0Ab\\x07\" Known keys: version, world, "
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
              "t.json: error: /entities/0/mass: expected a number > 0, got " + expected + "...");
}

// Review finding: a plane normal was divided by its own rounded length on
// every load, so {1, 2} moved in its last bit between the first and the
// second save, breaking "load, save, load, save gives identical bytes".
TEST(LoaderRegressions, APlaneNormalIsNormalisedOnceAndThenKeptBitForBit) {
    std::string first;
    const std::string second =
        saveLoadSave(R"({"entities": [{"plane": {"normal": {"x": 1, "y": 2}, "offset": 0.5}}]})", &first);
    EXPECT_EQ(second, first);
    EXPECT_NE(first.find(R"("normal": {"x": 0.4472135954999579, "y": 0.8944271909999159})"), std::string::npos) << first;
    EXPECT_NE(first.find(R"("offset": 0.22360679774997896)"), std::string::npos) << first;
}

// Review finding: |n| was sqrt(x*x + y*y), which overflows for a normal of
// 1e200: the plane became {0, 0} (saved, it no longer loads).
TEST(LoaderRegressions, AHugePlaneNormalIsNormalisedWithoutOverflow) {
    Result<Scene> scene = parseScene(R"({"entities": [{"plane": {"normal": {"x": 1e200, "y": 1e200}, "offset": 3}}]})", "t.json");
    ASSERT_TRUE(scene) << scene.error();
    const Plane* plane = scene->registry.tryGet<Plane>(scene->registry.entities()[0]);
    EXPECT_EQ(plane->normal, (Vec2{1.0 / std::sqrt(2.0), 1.0 / std::sqrt(2.0)}));
    EXPECT_EQ(plane->offset, 3.0 / std::hypot(1e200, 1e200));
}

// Review finding: an offset that overflows once divided by a tiny normal's
// length became inf, saved as null.
TEST(LoaderRegressions, APlaneOffsetThatOverflowsWhenNormalisedIsRefused) {
    EXPECT_EQ(refusal(R"({"entities": [{"plane": {"normal": {"x": 1e-11, "y": 0}, "offset": 1e300}}]})"),
              "t.json: error: /entities/0/plane/offset: expected an offset that stays finite once the normal is "
              "normalised (offset / |normal|), got 1e+300 with |normal| = 1e-11");
}

// Review finding: a spring without rest_length whose ends are too far apart
// got rest_length = inf, saved as null.
TEST(LoaderRegressions, ASpringWhoseLengthOverflowsNeedsAnExplicitRestLength) {
    EXPECT_EQ(refusal(R"({"entities": [{"name": "p", "position": {"x": -1e200, "y": 0}},
                                       {"spring": {"a": "p", "anchor": {"x": 1e200, "y": 0}}}]})"),
              "t.json: error: /entities/1/spring: the ends are too far apart to compute the length (over 1e154 m); "
              "give \"rest_length\"");
    // With one given, it loads and round-trips.
    std::string first;
    EXPECT_EQ(saveLoadSave(R"({"entities": [{"name": "p", "position": {"x": -1e200, "y": 0}},
                 {"spring": {"a": "p", "anchor": {"x": 1e200, "y": 0}, "rest_length": 1}}]})", &first),
              first);
}

// Found by the CLI limit test (not reachable by the fuzzer's 64 KiB inputs):
// nlohmann's parser callback rescans the enclosing array after every value,
// so refusing 1,000,001 entities took 3 minutes (and loading a million,
// as long). Linear now: ten times the entities must cost about ten times
// the time, far from the hundred times of the quadratic parser.
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
    timeToRefuse(20'000);  // warm up the allocator
    const double small = timeToRefuse(100'000);
    const double large = timeToRefuse(1'000'000);
    EXPECT_LT(large, 30.0 * small) << "100,001 entities: " << small << " s; 1,000,001: " << large << " s";
}

// The entity limit counts the objects of the top-level "entities" array
// only (the parser callback counted every object two levels down, so
// "gravity" in "world" was an entity too).
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

// docs/format.md: "JSON nested deeper than 16 levels is refused". The callback
// counted enclosing containers, so 17 levels passed. 16 levels now reach
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

// Every kept input (findings and hand-written edge cases) satisfies the
// fuzzer's property: refused with one line of UTF-8 naming the file, or
// loads and round-trips to identical bytes.
TEST(LoaderRegressions, EveryFileInTheFuzzCorpusSatisfiesTheFuzzersProperty) {
    int files = 0;
    for (const auto& entry : fs::directory_iterator(fs::path(STEPWISE_SOURCE_DIR) / "tests" / "fuzz" / "corpus")) {
        ++files;
        EXPECT_EQ(fuzz::checkLoaderProperty(readFile(entry.path())), "") << entry.path();
    }
    EXPECT_GE(files, 6);
}
