#include "templates.hpp"

#include "stepwise/component_table.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace stepwise::detail {

const std::string* templateOf(const Registry& reg, Entity e) {
    if (const Template* t = reg.tryGet<Template>(e)) return &t->value;
    Entity end;
    if (const Joint* j = reg.tryGet<Joint>(e)) end = j->a;
    else if (const Spring* s = reg.tryGet<Spring>(e)) end = s->a;
    if (end.isNull()) return nullptr;
    const Template* t = reg.tryGet<Template>(end);
    return t ? &t->value : nullptr;
}

bool isEmittedCopy(const Registry& reg, Entity e) {
    const Name* name = reg.tryGet<Name>(e);
    if (!name) return false;
    const std::size_t hash = name->value.find('#');
    if (hash == std::string::npos || hash == 0) return false;
    const std::string_view prefix(name->value.data(), hash);
    if (reg.count<Template>() == 0) return false;
    bool found = false;
    reg.each<Template>([&](Entity, const Template& t) { found = found || t.value == prefix; });
    return found;
}

std::vector<int> storedCopyNumbers(const std::vector<int>& numbers, int emitted) {
    const int alive = int(numbers.size());
    for (int i = 0; i < alive; ++i)
        if (numbers[std::size_t(i)] != emitted - alive + 1 + i) return numbers;
    return {};
}

std::optional<int> copyNumberIn(const std::string& name, const std::string& templateName) {
    const std::size_t n = templateName.size();
    if (name.size() <= n + 1 || name.compare(0, n, templateName) != 0 || name[n] != '#') return std::nullopt;
    const std::size_t end = std::min(name.find('/', n + 1), name.size());
    const std::string digits = name.substr(n + 1, end - n - 1);
    if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos)
        return std::nullopt;
    return std::stoi(digits);
}

namespace {

std::uint64_t splitMix64(std::uint64_t z) {
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

} // namespace


double emitterTurn(int seed, std::uint64_t key, int number, double spread) {
    if (spread == 0.0) return 0.0;
    const std::uint64_t bits =
        splitMix64(splitMix64(splitMix64(std::uint64_t(std::uint32_t(seed))) ^ key) ^ std::uint64_t(std::uint32_t(number)));
    // 53 random bits: u in [0, 1), then a uniform angle in [-spread, spread).
    const double u = double(bits >> 11) * 0x1.0p-53;
    return spread * (2.0 * u - 1.0);
}

std::uint64_t emitterKey(const Registry& reg, Entity emitter, std::size_t sceneIndex) {
    const Name* name = reg.tryGet<Name>(emitter);
    if (!name || name->value.empty()) return splitMix64(sceneIndex);
    std::uint64_t h = 0xCBF29CE484222325ull;  // FNV-1a
    for (const char c : name->value) {
        h ^= std::uint8_t(c);
        h *= 0x100000001B3ull;
    }
    return h;
}

} // namespace stepwise::detail
