#pragma once
// The text layer of the level loader: level text -> JSON DOM, with the
// loader's limits and rules enforced while parsing, so a hostile file is
// refused before its DOM is built. Component parsing (scene_json.cpp) only
// ever sees a DOM that passed these checks.

#include "stepwise/result.hpp"
#include "stepwise/scene_io.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <string_view>

namespace stepwise::detail {

using LevelJson = nlohmann::ordered_json;

/// Parses `text` into `root`. On failure returns the whole message:
/// "NAME:LINE:COL: error: ..." where the text has a place (syntax, a
/// duplicate key, a NUL byte, a limit passed), else "NAME: error: ...".
/// Rules checked on the way (docs/format.md, "Limits"):
///  - no NUL byte anywhere (nlohmann stops at one as at the end of input);
///  - no key twice in one object (the second is named by its JSON Pointer);
///  - nesting depth, entity count, JSON values in the file and in one
///    entity (LoadLimits), counted while parsing;
///  - an element of "entities" that is an array or the top level that is
///    an array is refused at its first child, not after its DOM is built.
Result<void> parseLevelJson(std::string_view text, std::string_view sourceName, const LoadLimits& limits,
                            LevelJson& root);

/// A key as a JSON Pointer token (RFC 6901): "~" -> "~0", "/" -> "~1".
std::string escapePointerToken(std::string_view token);

/// Messages quote names and values from the file: a run of more than 120
/// bytes without a space, quote, slash or colon is cut to its first 60 bytes and
/// "...(N bytes)", and the whole message to 4,096 bytes, so a 10 MB key
/// gives a one-line message, not a 20 MB one.
std::string shortenForMessage(std::string_view message);

} // namespace stepwise::detail
