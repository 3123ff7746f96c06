#include "app/script.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>

namespace stepwise::editor {

namespace {

std::vector<std::string> splitWords(const std::string& line, std::string& quoted, bool& hasQuoted) {
    std::vector<std::string> words;
    hasQuoted = false;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        if (i >= line.size()) break;
        if (line[i] == '"') {
            const std::size_t end = line.find('"', i + 1);
            quoted = line.substr(i + 1, end == std::string::npos ? std::string::npos : end - i - 1);
            hasQuoted = true;
            words.push_back(quoted);
            i = end == std::string::npos ? line.size() : end + 1;
            continue;
        }
        std::size_t j = i;
        while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
        words.push_back(line.substr(i, j - i));
        i = j;
    }
    return words;
}

bool toNumber(const std::string& s, double& out) {
    if (s.empty()) return false;
    char* end = nullptr;
    out = std::strtod(s.c_str(), &end);
    return end == s.c_str() + s.size() && std::isfinite(out);
}

} // namespace

Result<std::pair<Key, std::uint8_t>> parseChord(std::string_view chord) {
    std::uint8_t mods = kModNone;
    std::string rest(chord);
    for (;;) {
        const auto plus = rest.find('+');
        if (plus == std::string::npos || plus + 1 == rest.size()) break;
        const std::string original = rest.substr(0, plus);
        std::string mod = original;
        for (char& c : mod) c = char(std::tolower(static_cast<unsigned char>(c)));
        if (mod == "ctrl" || mod == "control") mods |= kModCtrl;
        else if (mod == "shift") mods |= kModShift;
        else if (mod == "alt") mods |= kModAlt;
        else return Error{"unknown modifier \"" + original + "\" (expected Ctrl, Shift or Alt)"};
        rest = rest.substr(plus + 1);
    }
    const std::optional<Key> key = keyFromName(rest);
    if (!key) return Error{"unknown key \"" + rest + "\" (letters, digits, Space, Left, Right, Up, Down, Delete, "
                           "Backspace, Escape, Enter, Tab, F1..F5)"};
    return std::make_pair(*key, mods);
}

Result<std::vector<ScriptCommand>> parseScript(std::string_view text, std::string_view name) {
    std::vector<ScriptCommand> out;
    std::istringstream in{std::string(text)};
    int lineNo = 0;
    static const std::set<std::string, std::less<>> kActions{
        "play", "pause", "step", "stepback", "reset", "undo", "redo", "tool", "select", "overlay", "system",
        "snap", "timescale", "breakon", "fit", "new", "open", "save", "saveas", "savestate", "screenshot", "window", "tab"};
    for (std::string line; std::getline(in, line);) {
        ++lineNo;
        if (const auto hash = line.find('#'); hash != std::string::npos && line.find('"') == std::string::npos)
            line.resize(hash);
        std::string quoted;
        bool hasQuoted = false;
        std::vector<std::string> w = splitWords(line, quoted, hasQuoted);
        if (w.empty()) continue;
        auto fail = [&](const std::string& what) {
            return Error{std::string(name) + ":" + std::to_string(lineNo) + ": " + what};
        };
        ScriptCommand c;
        c.line = lineNo;
        const std::string& verb = w[0];
        // Reads "[world] X Y" starting at w[i]; advances i.
        auto point = [&](std::size_t& i, ScriptPoint& p) -> bool {
            p.world = false;
            if (i < w.size() && w[i] == "world") {
                p.world = true;
                ++i;
            }
            if (i + 2 > w.size()) return false;
            if (!toNumber(w[i], p.value.x) || !toNumber(w[i + 1], p.value.y)) return false;
            i += 2;
            return true;
        };
        if (verb == "key" || verb == "keydown" || verb == "keyup") {
            if (w.size() != 2) return fail("expected: " + verb + " KEY (e.g. key Ctrl+Z)");
            Result<std::pair<Key, std::uint8_t>> chord = parseChord(w[1]);
            if (!chord) return fail(chord.error());
            c.kind = verb == "key" ? ScriptCommand::Kind::Key
                     : verb == "keydown" ? ScriptCommand::Kind::KeyDown
                                         : ScriptCommand::Kind::KeyUp;
            c.key = chord->first;
            c.mods = chord->second;
        } else if (verb == "move" || verb == "click") {
            std::size_t i = 1;
            if (!point(i, c.a)) return fail("expected: " + verb + " [world] X Y");
            c.kind = verb == "move" ? ScriptCommand::Kind::Move : ScriptCommand::Kind::Click;
            c.hasPoint = true;
            for (; i < w.size(); ++i) {
                if (w[i] == "right") c.button = MouseButton::Right;
                else if (w[i] == "middle") c.button = MouseButton::Middle;
                else if (w[i] == "left") c.button = MouseButton::Left;
                else if (w[i] == "shift") c.mods |= kModShift;
                else if (w[i] == "ctrl") c.mods |= kModCtrl;
                else return fail("unexpected \"" + w[i] + "\" (expected left, right, middle, shift or ctrl)");
            }
        } else if (verb == "drag") {
            std::size_t i = 1;
            c.kind = ScriptCommand::Kind::Drag;
            if (!point(i, c.a)) return fail("expected: drag [world] X0 Y0 X1 Y1 [MOVES] [right|middle]");
            const bool world = c.a.world;
            c.b.world = world;
            if (i + 2 > w.size() || !toNumber(w[i], c.b.value.x) || !toNumber(w[i + 1], c.b.value.y))
                return fail("expected: drag [world] X0 Y0 X1 Y1 [MOVES] [right|middle]");
            i += 2;
            c.count = 8;
            for (; i < w.size(); ++i) {
                double n = 0;
                if (w[i] == "right") c.button = MouseButton::Right;
                else if (w[i] == "middle") c.button = MouseButton::Middle;
                else if (w[i] == "shift") c.mods |= kModShift;
                else if (w[i] == "ctrl") c.mods |= kModCtrl;
                else if (toNumber(w[i], n) && n >= 1 && n <= 1000) c.count = int(n);
                else return fail("unexpected \"" + w[i] + "\" (expected a move count 1..1000, right, middle, shift or ctrl)");
            }
            c.hasPoint = true;
        } else if (verb == "wheel") {
            c.kind = ScriptCommand::Kind::Wheel;
            if (w.size() < 2 || !toNumber(w[1], c.number)) return fail("expected: wheel NOTCHES [[world] X Y]");
            std::size_t i = 2;
            if (i < w.size()) {
                if (!point(i, c.a)) return fail("expected: wheel NOTCHES [[world] X Y]");
                c.hasPoint = true;
            }
        } else if (verb == "text") {
            if (!hasQuoted) return fail("expected: text \"TEXT\"");
            c.kind = ScriptCommand::Kind::Text;
            c.text = quoted;
        } else if (verb == "wait") {
            double n = 0;
            if (w.size() != 2 || !toNumber(w[1], n) || n < 0 || n > 1e6) return fail("expected: wait FRAMES (0..1000000)");
            c.kind = ScriptCommand::Kind::Wait;
            c.count = int(n);
        } else if (kActions.count(verb)) {
            c.kind = ScriptCommand::Kind::Action;
            c.text = verb;
            c.args.assign(w.begin() + 1, w.end());
            const std::size_t n = c.args.size();
            auto needs = [&](std::size_t lo, std::size_t hi, const char* usage) -> std::optional<Error> {
                if (n < lo || n > hi) return fail(std::string("expected: ") + usage);
                return std::nullopt;
            };
            std::optional<Error> bad;
            if (verb == "step" || verb == "stepback") {
                bad = needs(0, 1, (verb + " [N]").c_str());
                double k = 1;
                if (!bad && n == 1 && (!toNumber(c.args[0], k) || k < 1 || k > 100000)) bad = fail("N must be 1..100000");
                c.count = int(k);
            } else if (verb == "tool") bad = needs(1, 1, "tool select|rotate|circle|box|plane|spring|attractor|boids");
            else if (verb == "select") bad = needs(1, 1000, "select NAME... | select none | select all");
            else if (verb == "overlay" || verb == "system" || verb == "window")
                bad = needs(2, 2, (verb + " NAME on|off").c_str());
            else if (verb == "tab") bad = needs(1, 1, "tab contacts|plots|profile|history");
            else if (verb == "snap") bad = needs(1, 1, "snap on|off");
            else if (verb == "timescale") {
                bad = needs(1, 1, "timescale X");
                if (!bad && (!toNumber(c.args[0], c.number) || c.number < 0)) bad = fail("timescale: expected a number >= 0");
            } else if (verb == "breakon") bad = needs(1, 1, "breakon NAME|none");
            else if (verb == "open" || verb == "saveas" || verb == "savestate" || verb == "screenshot")
                bad = needs(1, 1, (verb + " PATH").c_str());
            else bad = needs(0, 0, verb.c_str());
            if (bad) return *bad;
        } else {
            return fail("unknown command \"" + verb +
                        "\" (expected key, keydown, keyup, move, click, drag, wheel, text, wait, or an action: play, "
                        "pause, step, stepback, reset, undo, redo, tool, select, overlay, system, snap, timescale, "
                        "breakon, fit, new, open, save, saveas, savestate, screenshot, window, tab)");
        }
        out.push_back(std::move(c));
    }
    return out;
}

} // namespace stepwise::editor
