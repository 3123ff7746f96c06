#pragma once
// The property the loader fuzzer checks on every input, shared with the
// regression test that replays fuzz/corpus/ (tests/test_loader_regressions.cpp)
// so a finding kept in the corpus is checked by ctest in every build, not
// only by clang's fuzz build.
//
// Every input is either refused with one well-formed message, or loads; and
// whatever loads saves, loads again and saves to the same bytes (docs/format.md:
// "load, save, load, save gives identical bytes").

#include "stepwise/scene_io.hpp"

#include <string>
#include <string_view>

namespace stepwise::fuzz {

/// Refusals are printed on a terminal and shown in the editor's UI: one line
/// of valid UTF-8 that starts with "FILE:".
inline bool isValidUtf8(std::string_view s) {
    std::size_t i = 0;
    while (i < s.size()) {
        const auto c = static_cast<unsigned char>(s[i]);
        const std::size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
        if (n == 0 || i + n > s.size()) return false;
        for (std::size_t k = 1; k < n; ++k)
            if ((static_cast<unsigned char>(s[i + k]) >> 6) != 0x2) return false;
        i += n;
    }
    return true;
}

/// "" when `text` behaves, else what went wrong (with the texts involved).
inline std::string checkLoaderProperty(std::string_view text) {
    constexpr std::string_view kSource = "fuzz.json";
    Result<Scene> scene = parseScene(text, kSource);
    if (!scene) {
        const std::string& message = scene.error();
        if (message.compare(0, kSource.size(), kSource) != 0 || message.size() <= kSource.size() ||
            message[kSource.size()] != ':')
            return "refusal does not start with the file name: " + message;
        if (message.find('\n') != std::string::npos) return "refusal spans more than one line: " + message;
        if (!isValidUtf8(message)) return "refusal is not valid UTF-8: " + message;
        // Long names and values are cut (json_reader.cpp): a message is at
        // most 4,096 bytes plus the note saying it was cut.
        if (message.size() > 4200) return "refusal is " + std::to_string(message.size()) + " bytes long";
        return {};
    }
    // nlohmann's lexer stops at a NUL as at the end of the input; a level
    // file has none, so nothing with one may load.
    if (text.find('\0') != std::string_view::npos) return "a text with a NUL byte loaded";
    const std::string first = sceneToJsonText(*scene);
    Result<Scene> again = parseScene(first, "saved.json");
    if (!again) return "a loaded scene saved text that does not load: " + again.error() + "\n--- saved text:\n" + first;
    const std::string second = sceneToJsonText(*again);
    if (first != second)
        return "load -> save -> load -> save is not byte-identical\n--- first save:\n" + first + "--- second save:\n" +
               second;
    return {};
}

} // namespace stepwise::fuzz
