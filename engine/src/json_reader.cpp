// The text layer of the level loader (json_reader.hpp): nlohmann's SAX
// parser driving its own DOM builder, with a handler in front that checks
// the limits and rules as each value arrives. Work and memory are bounded
// per input byte and in total for every shape of JSON: every value counts
// towards LoadLimits::maxValues (the DOM costs 16 to about 120 bytes per
// value), nesting is bounded by maxDepth, and duplicate-key bookkeeping is
// 16 bytes per key of the objects currently open.

#include "json_reader.hpp"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <functional>
#include <iterator>
#include <unordered_map>
#include <utility>
#include <vector>

namespace stepwise::detail {

namespace {

using Json = LevelJson;

/// 1-based line and column (in bytes) of byte offset `offset`.
std::pair<std::size_t, std::size_t> lineColumn(std::string_view text, std::size_t offset) {
    offset = std::min(offset, text.size());
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < offset; ++i) {
        if (text[i] == '\n') {
            ++line;
            column = 1;
        } else {
            ++column;
        }
    }
    return {line, column};
}

std::string place(std::string_view text, std::size_t offset, std::string_view sourceName) {
    const auto [line, column] = lineColumn(text, offset);
    return std::string(sourceName) + ":" + std::to_string(line) + ":" + std::to_string(column);
}

/// Message for a JSON syntax error at byte `offset` (0-based, at the
/// offending character), with hints for the two mistakes people make most.
std::string syntaxMessage(std::string_view text, std::size_t offset, std::string_view sourceName,
                          std::string detail) {
    // Typographic quotes (U+2018/2019/201C/201D, UTF-8 E2 80 98..9D) pasted
    // from slides: point at the first one, wherever the parser gave up.
    for (std::size_t i = 0; i + 2 < text.size(); ++i) {
        if (static_cast<unsigned char>(text[i]) == 0xE2 && static_cast<unsigned char>(text[i + 1]) == 0x80) {
            const unsigned char c = static_cast<unsigned char>(text[i + 2]);
            if (c == 0x9C || c == 0x9D || c == 0x98 || c == 0x99) {
                const bool dbl = c == 0x9C || c == 0x9D;
                return place(text, i, sourceName) + ": error: typographic quote " + std::string(text.substr(i, 3)) +
                       " where JSON needs a straight quote " + (dbl ? "\"" : "\" (JSON strings use double quotes)") +
                       "; text pasted from slides or a word processor has these. Replace every “ ” ‘ ’ with \"";
            }
        }
    }
    // Trailing comma: the parser stops at '}' or ']' right after a ','.
    if (offset < text.size() && (text[offset] == '}' || text[offset] == ']')) {
        std::size_t j = offset;
        while (j > 0 && std::isspace(static_cast<unsigned char>(text[j - 1]))) --j;
        if (j > 0 && text[j - 1] == ',') {
            return place(text, j - 1, sourceName) + ": error: trailing comma before '" + text[offset] +
                   "'; JSON allows no comma after the last element. Remove this comma";
        }
    }
    return place(text, offset, sourceName) + ": error: " + detail;
}

/// The part of nlohmann's parse_error text after its "line L, column C: "
/// prefix (we compute line and column ourselves, in bytes).
std::string parserDetail(const std::string& what) {
    const auto pos = what.find(": ", what.find("parse error"));
    std::string detail = pos == std::string::npos ? what : what.substr(pos + 2);
    return detail.empty() ? "not valid JSON" : detail;
}

/// Values allowed inside the top-level "world" and "view" objects (a world
/// has about 15).
constexpr std::size_t kMaxSectionValues = 10'000;

/// A limit passed or a rule broken while parsing: thrown by the handler,
/// caught in parseLevelJson. `offset` is where (npos: the message has no
/// place, as for the entity and depth limits).
struct Stop {
    std::string message;
    std::size_t offset = std::string_view::npos;
};

/// A wrong shape found early; formatted as scene_json.cpp formats the same
/// refusal found later ("NAME: error: /pointer: message").
struct ShapeStop {
    std::string pointer;
    std::string message;
};

/// A const char* that tells the handler how far the lexer has read: the
/// handler's callbacks carry no position, but nlohmann's lexer reads one
/// character at a time through this iterator, so after a string token the
/// cursor is just past its closing quote.
class TrackedIterator {
public:
    using iterator_category = std::input_iterator_tag;
    using value_type = char;
    using difference_type = std::ptrdiff_t;
    using pointer = const char*;
    using reference = const char&;

    TrackedIterator(const char* p, const char** cursor) : p_(p), cursor_(cursor) {}
    reference operator*() const { return *p_; }
    TrackedIterator& operator++() {
        *cursor_ = ++p_;
        return *this;
    }
    TrackedIterator operator++(int) {
        TrackedIterator before = *this;
        ++*this;
        return before;
    }
    bool operator==(const TrackedIterator& o) const { return p_ == o.p_; }
    bool operator!=(const TrackedIterator& o) const { return p_ != o.p_; }

private:
    const char* p_;
    const char** cursor_;
};

/// nlohmann's DOM builder (the one Json::parse uses) with the loader's
/// rules checked on the way. Not nlohmann's parser callback: after every
/// value it scans the whole enclosing array for a discarded element, so
/// refusing 1,000,001 entities takes 3 minutes (quadratic). This handler
/// forwards to the plain DOM builder, which is linear.
class CheckedDomBuilder {
public:
    using Dom = nlohmann::detail::json_sax_dom_parser<Json>;

    CheckedDomBuilder(Json& root, const LoadLimits& limits, std::string_view text, const char* const* cursor)
        : dom_(root, /*allow_exceptions=*/true), limits_(limits), text_(text), cursor_(cursor) {
        frames_.resize(std::size_t(std::max(limits.maxDepth, 0)) + 1);
    }

    bool null() {
        beginValue();
        return dom_.null();
    }
    bool boolean(bool v) {
        beginValue();
        return dom_.boolean(v);
    }
    bool number_integer(Json::number_integer_t v) {
        beginValue();
        return dom_.number_integer(v);
    }
    bool number_unsigned(Json::number_unsigned_t v) {
        beginValue();
        return dom_.number_unsigned(v);
    }
    bool number_float(Json::number_float_t v, const Json::string_t& s) {
        beginValue();
        return dom_.number_float(v, s);
    }
    bool string(Json::string_t& v) {
        beginValue();
        return dom_.string(v);
    }
    bool binary(Json::binary_t& v) {
        beginValue();
        return dom_.binary(v);
    }
    bool key(Json::string_t& k) {
        Frame& frame = frames_[std::size_t(open_ - 1)];
        if (++frame.keys > limits_.maxKeysPerObject)
            throw Stop{(open_ > 1 ? pointerTo(open_ - 1) + ": " : std::string()) + "more than " +
                           std::to_string(limits_.maxKeysPerObject) + " keys in one object; the limit is " +
                           std::to_string(limits_.maxKeysPerObject) + " (a level's objects have about 20)",
                       keyStart(offset())};
        checkDuplicate(frame, k);
        frame.key = k;
        return dom_.key(k);
    }
    bool start_object(std::size_t n) {
        beginValue();
        enter(true);
        if (open_ == 3 && inEntities() && ++entities_ > limits_.maxEntities)
            throw Stop{"more than " + std::to_string(limits_.maxEntities) + " entities; the limit is " +
                       std::to_string(limits_.maxEntities)};
        return dom_.start_object(n);
    }
    bool end_object() {
        --open_;
        return dom_.end_object();
    }
    bool start_array(std::size_t n) {
        beginValue();
        enter(false);
        return dom_.start_array(n);
    }
    bool end_array() {
        --open_;
        return dom_.end_array();
    }
    template <class Exception>
    bool parse_error(std::size_t position, const std::string& token, const Exception& e) {
        return dom_.parse_error(position, token, e);
    }

private:
    struct Frame {
        bool object = false;
        std::string key;        ///< object: the key of the current member
        std::size_t index = 0;  ///< array: elements started so far
        /// Keys seen in this object: hash of the key -> offset just past its
        /// closing quote. A vector while small (most objects have 2 to 6
        /// keys), a hash map past 16.
        std::vector<std::pair<std::uint64_t, std::size_t>> smallKeys;
        std::unordered_map<std::uint64_t, std::size_t> bigKeys;
        std::size_t keys = 0;  ///< keys read in this object
    };

    std::size_t offset() const { return std::size_t(*cursor_ - text_.data()); }

    /// Offset of the last character of the value just read. The lexer has
    /// read one character past a number (and put it back), so step back
    /// over that delimiter and any blanks.
    std::size_t valueEnd() const {
        std::size_t p = offset() ? offset() - 1 : 0;
        const auto delimiter = [](char c) { return c == ',' || c == ']' || c == '}' || c == ':' || std::isspace(static_cast<unsigned char>(c)); };
        while (p > 0 && delimiter(text_[p])) --p;
        return p;
    }

    bool inEntities() const {
        return open_ >= 2 && frames_[0].object && frames_[0].key == "entities" && !frames_[1].object;
    }

    /// The JSON Pointer of the value being read in frame `depth - 1`'s
    /// current member (object key or array element).
    std::string pointerTo(int depth) const {
        std::string out;
        for (int d = 0; d < depth; ++d) {
            const Frame& f = frames_[std::size_t(d)];
            out += "/" + (f.object ? escapePointerToken(f.key) : std::to_string(f.index - 1));
        }
        return out;
    }

    /// Every value (scalar or container) passes here before the DOM sees it.
    void beginValue() {
        if (++values_ > limits_.maxValues)
            throw Stop{"more than " + std::to_string(limits_.maxValues) +
                           " JSON values (numbers, strings, objects, arrays); the limit is " +
                           std::to_string(limits_.maxValues) + " (a level uses about 14 per entity)",
                       valueEnd()};
        if (open_ == 0) return;
        Frame& parent = frames_[std::size_t(open_ - 1)];
        if (!parent.object) ++parent.index;
        // Wrong shapes refused at their first child, before a DOM of
        // millions of values is built only to be thrown away. Same messages
        // as scene_json.cpp gives for a non-empty container there.
        if (open_ == 1 && !parent.object)
            throw ShapeStop{"", "expected a level object {\"entities\": [...]}, got an array"};
        if (open_ == 2 && frames_[0].object && frames_[0].key == "entities" && parent.object)
            throw ShapeStop{"/entities", "expected an array of entities, got an object"};
        if (open_ == 2 && inEntities()) entityStart_ = values_;
        // "world" and "view" hold a dozen values; a huge array there would
        // otherwise be built in full before the component layer refuses it.
        if (open_ == 1 && parent.object && (parent.key == "world" || parent.key == "view")) sectionStart_ = values_;
        if (open_ >= 2 && frames_[0].object && (frames_[0].key == "world" || frames_[0].key == "view") &&
            values_ - sectionStart_ > kMaxSectionValues)
            throw Stop{"/" + frames_[0].key + ": more than " + std::to_string(kMaxSectionValues) +
                           " JSON values; this section holds a few settings",
                       valueEnd()};
        if (open_ == 3 && inEntities() && !parent.object)
            throw ShapeStop{pointerTo(2), "expected an entity object {\"component\": value, ...}, got an array"};
        if (open_ >= 3 && inEntities() && values_ - entityStart_ >= limits_.maxValuesPerEntity)
            throw Stop{pointerTo(2) + ": more than " + std::to_string(limits_.maxValuesPerEntity) +
                           " JSON values in one entity; the limit is " + std::to_string(limits_.maxValuesPerEntity),
                       valueEnd()};
    }

    void enter(bool object) {
        // open_ counts the containers open including this one: the root
        // object is level 1, an entity level 3, a vector in it level 4.
        if (++open_ > limits_.maxDepth)
            throw Stop{"JSON nesting deeper than " + std::to_string(limits_.maxDepth) +
                       " levels; a level file needs 4"};
        Frame& f = frames_[std::size_t(open_ - 1)];
        f.object = object;
        f.key.clear();
        f.index = 0;
        f.smallKeys.clear();
        f.bigKeys.clear();
        f.keys = 0;
    }

    /// Offset of the opening quote of the key whose closing quote is at
    /// `end - 1`: the first quote before it not escaped by a backslash.
    std::size_t keyStart(std::size_t end) const {
        std::size_t i = end - 1;
        while (i > 0) {
            --i;
            if (text_[i] != '"') continue;
            std::size_t slashes = 0;
            while (slashes < i && text_[i - 1 - slashes] == '\\') ++slashes;
            if (slashes % 2 == 0) return i;
        }
        return 0;
    }

    void checkDuplicate(Frame& frame, const std::string& key) {
        const std::size_t end = offset();
        const std::uint64_t hash = std::hash<std::string>{}(key);
        std::size_t earlier = std::string_view::npos;
        if (frame.bigKeys.empty()) {
            for (const auto& [h, at] : frame.smallKeys)
                if (h == hash && sameKey(at, key)) earlier = at;
        } else if (const auto it = frame.bigKeys.find(hash); it != frame.bigKeys.end() && sameKey(it->second, key)) {
            earlier = it->second;
        }
        if (earlier != std::string_view::npos) {
            const auto [line, column] = lineColumn(text_, keyStart(earlier));
            throw Stop{pointerTo(open_ - 1) + "/" + escapePointerToken(key) + ": duplicate key \"" + key +
                           "\" (first at line " + std::to_string(line) + ", column " + std::to_string(column) +
                           "); a key may appear once in an object",
                       keyStart(end)};
        }
        if (frame.bigKeys.empty() && frame.smallKeys.size() < 16) {
            frame.smallKeys.emplace_back(hash, end);
            return;
        }
        if (frame.bigKeys.empty())
            for (const auto& [h, at] : frame.smallKeys) frame.bigKeys.emplace(h, at);
        // Two different keys with one 64-bit hash: the later one is not
        // tracked (a missed duplicate at worst, never a false refusal).
        frame.bigKeys.emplace(hash, end);
    }

    /// Whether the key that ended at `end` (as written in the file, escapes
    /// and all) decodes to `key`.
    bool sameKey(std::size_t end, const std::string& key) const {
        const std::size_t start = keyStart(end);
        if (end - start == key.size() + 2 && text_.compare(start + 1, key.size(), key) == 0) return true;
        try {
            return Json::parse(text_.substr(start, end - start)).get<std::string>() == key;
        } catch (const Json::exception&) {
            return false;
        }
    }

    Dom dom_;
    const LoadLimits& limits_;
    std::string_view text_;
    const char* const* cursor_;
    std::vector<Frame> frames_;  ///< [d] = the container open at depth d + 1
    int open_ = 0;
    std::size_t entities_ = 0;
    std::size_t values_ = 0;
    std::size_t entityStart_ = 0;   ///< values_ when the current entity began
    std::size_t sectionStart_ = 0;  ///< values_ when "world" or "view" began
};

} // namespace

Result<void> parseLevelJson(std::string_view text, std::string_view sourceName, const LoadLimits& limits,
                            LevelJson& root) {
    const std::string prefix = std::string(sourceName) + ": error: ";
    // nlohmann's lexer takes a NUL byte for the end of the input, so a
    // level followed by a NUL and anything at all would load.
    if (const void* nul = std::memchr(text.data(), 0, text.size()))
        return Error{place(text, std::size_t(static_cast<const char*>(nul) - text.data()), sourceName) +
                     ": error: a NUL byte; a level file is text and has none (a file cut short or padded by a "
                     "crash often ends in NUL bytes)"};
    const char* cursor = text.data();
    try {
        CheckedDomBuilder sax(root, limits, text, &cursor);
        Json::sax_parse(TrackedIterator(text.data(), &cursor), TrackedIterator(text.data() + text.size(), &cursor),
                        &sax, nlohmann::detail::input_format_t::json, /*strict=*/true, /*ignore_comments=*/false);
    } catch (const Stop& stop) {
        root = Json();
        if (stop.offset == std::string_view::npos) return Error{prefix + stop.message};
        return Error{place(text, stop.offset, sourceName) + ": error: " + stop.message};
    } catch (const ShapeStop& stop) {
        root = Json();
        return Error{prefix + (stop.pointer.empty() ? "" : stop.pointer + ": ") + stop.message};
    } catch (const Json::parse_error& e) {
        root = Json();
        // e.byte is 1-based and points just past the offending character.
        const std::size_t offset = e.byte > 0 ? e.byte - 1 : 0;
        return Error{syntaxMessage(text, offset, sourceName, parserDetail(e.what()))};
    } catch (const Json::out_of_range& e) {
        root = Json();
        // A number literal beyond double range (1e999): nlohmann names the
        // literal but not its position, so find the literal in the text.
        const std::string what = e.what();
        const auto open = what.find('\''), close = what.rfind('\'');
        const std::string literal =
            open != std::string::npos && close > open ? what.substr(open + 1, close - open - 1) : std::string();
        const std::size_t at = literal.empty() ? std::string_view::npos : text.find(literal);
        return Error{place(text, at == std::string_view::npos ? 0 : at, sourceName) + ": error: number " + literal +
                     " is out of double range; expected a finite number"};
    } catch (const Json::exception& e) {
        root = Json();
        return Error{prefix + "not a valid level: " + e.what()};
    }
    return {};
}

std::string escapePointerToken(std::string_view token) {
    std::string out;
    for (char c : token) {
        if (c == '~') out += "~0";
        else if (c == '/') out += "~1";
        else out += c;
    }
    return out;
}

std::string shortenForMessage(std::string_view message) {
    constexpr std::size_t kLongRun = 120, kKeep = 60, kMaxMessage = 4096;
    std::string out;
    out.reserve(std::min(message.size(), kMaxMessage + 64));
    std::size_t i = 0;
    while (i < message.size()) {
        std::size_t j = i;
        while (j < message.size() && message[j] != ' ' && message[j] != '"' && message[j] != '/' && message[j] != ':') ++j;
        if (j - i > kLongRun) {
            // Cut on a UTF-8 character boundary, never inside a character.
            std::size_t cut = i + kKeep;
            while (cut > i && (static_cast<unsigned char>(message[cut]) & 0xC0) == 0x80) --cut;
            out.append(message.substr(i, cut - i));
            out += "...(" + std::to_string(j - i) + " bytes)";
        } else {
            out.append(message.substr(i, j - i));
        }
        if (j < message.size()) out += message[j];
        i = j + 1;
        if (out.size() > kMaxMessage) {
            std::size_t cut = kMaxMessage;
            while (cut > 0 && (static_cast<unsigned char>(out[cut]) & 0xC0) == 0x80) --cut;
            out.resize(cut);
            out += "...(message cut: " + std::to_string(message.size()) + " bytes)";
            break;
        }
    }
    return out;
}

} // namespace stepwise::detail
