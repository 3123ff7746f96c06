#include "app/script.hpp"

#include "app/script_actions.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
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

} // namespace

bool parseScriptNumber(const std::string& s, double& out) {
    if (s.empty()) return false;
    char* end = nullptr;
    out = std::strtod(s.c_str(), &end);
    return end == s.c_str() + s.size() && std::isfinite(out);
}

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
            if (!parseScriptNumber(w[i], p.value.x) || !parseScriptNumber(w[i + 1], p.value.y)) return false;
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
            if (i + 2 > w.size() || !parseScriptNumber(w[i], c.b.value.x) || !parseScriptNumber(w[i + 1], c.b.value.y))
                return fail("expected: drag [world] X0 Y0 X1 Y1 [MOVES] [right|middle]");
            i += 2;
            c.count = 8;
            for (; i < w.size(); ++i) {
                double n = 0;
                if (w[i] == "right") c.button = MouseButton::Right;
                else if (w[i] == "middle") c.button = MouseButton::Middle;
                else if (w[i] == "shift") c.mods |= kModShift;
                else if (w[i] == "ctrl") c.mods |= kModCtrl;
                else if (parseScriptNumber(w[i], n) && n >= 1 && n <= 1000) c.count = int(n);
                else return fail("unexpected \"" + w[i] + "\" (expected a move count 1..1000, right, middle, shift or ctrl)");
            }
            c.hasPoint = true;
        } else if (verb == "wheel") {
            c.kind = ScriptCommand::Kind::Wheel;
            if (w.size() < 2 || !parseScriptNumber(w[1], c.number)) return fail("expected: wheel NOTCHES [[world] X Y]");
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
            if (w.size() != 2 || !parseScriptNumber(w[1], n) || n < 0 || n > 1e6) return fail("expected: wait FRAMES (0..1000000)");
            c.kind = ScriptCommand::Kind::Wait;
            c.count = int(n);
        } else if (const ScriptAction* action = findScriptAction(verb)) {
            c.kind = ScriptCommand::Kind::Action;
            c.text = verb;
            c.args.assign(w.begin() + 1, w.end());
            const std::size_t n = c.args.size();
            if (n < action->minArgs || n > action->maxArgs) return fail("expected: " + action->usage);
            if (action->parse)
                if (Result<void> parsed = action->parse(c); !parsed) return fail(parsed.error());
        } else {
            std::string actions;
            for (const ScriptAction& a : scriptActions()) actions += (actions.empty() ? "" : ", ") + a.name;
            return fail("unknown command \"" + verb +
                        "\" (expected key, keydown, keyup, move, click, drag, wheel, text, wait, or an action: " +
                        actions + ")");
        }
        out.push_back(std::move(c));
    }
    return out;
}

} // namespace stepwise::editor
