#include "app/events.hpp"

#include <array>
#include <cctype>

namespace stepwise::editor {

namespace {
struct Named {
    std::string_view name;
    Key key;
};
constexpr std::array kNamed{
    Named{"Space", Key::Space},     Named{"Left", Key::Left},         Named{"Right", Key::Right},
    Named{"Up", Key::Up},           Named{"Down", Key::Down},         Named{"Delete", Key::Delete},
    Named{"Backspace", Key::Backspace}, Named{"Escape", Key::Escape}, Named{"Enter", Key::Enter},
    Named{"Tab", Key::Tab},         Named{"Home", Key::Home},         Named{"End", Key::End},
    Named{"PageUp", Key::PageUp},   Named{"PageDown", Key::PageDown}, Named{"F1", Key::F1},
    Named{"F2", Key::F2},           Named{"F3", Key::F3},             Named{"F4", Key::F4},
    Named{"F5", Key::F5},
};

bool equalNoCase(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
    return true;
}
} // namespace

std::optional<Key> keyFromName(std::string_view name) {
    for (const Named& n : kNamed)
        if (equalNoCase(n.name, name)) return n.key;
    if (equalNoCase(name, "Esc")) return Key::Escape;
    if (equalNoCase(name, "Del")) return Key::Delete;
    if (name.size() == 1) {
        const char c = char(std::toupper(static_cast<unsigned char>(name[0])));
        if (c >= 'A' && c <= 'Z') return Key(std::uint16_t(Key::A) + std::uint16_t(c - 'A'));
        if (c >= '0' && c <= '9') return Key(std::uint16_t(Key::Num0) + std::uint16_t(c - '0'));
    }
    return std::nullopt;
}

std::string_view keyName(Key key) {
    for (const Named& n : kNamed)
        if (n.key == key) return n.name;
    static const std::string_view letters = "ABCDEFGHIJKLMNOPQRSTUVWXYZ";
    static const std::string_view digits = "0123456789";
    if (key >= Key::A && key <= Key::Z) return letters.substr(std::size_t(key) - std::size_t(Key::A), 1);
    if (key >= Key::Num0 && key <= Key::Num9) return digits.substr(std::size_t(key) - std::size_t(Key::Num0), 1);
    return "?";
}

} // namespace stepwise::editor
