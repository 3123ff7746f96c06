#include "cli/cli_common.hpp"

#include "stepwise/component_table.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include <cerrno>
#include <cstdlib>
#include <iostream>

namespace stepwise::cli {

void reportError(const std::string& message) { std::cerr << "stepwise: error: " << message << "\n"; }

std::optional<Scene> loadLevelOrReport(const std::string& path) {
    Result<Scene> scene = loadSceneFile(path);
    if (!scene) {
        // The loader's message already names the file and the place.
        std::cerr << scene.error() << "\n";
        return std::nullopt;
    }
    return std::move(scene.value());
}

std::string sceneSummary(const Scene& scene) {
    const Registry& registry = scene.registry;
    std::string components;
    for (const ComponentInfo& info : componentTable()) {
        std::size_t count = 0;
        for (Entity e : registry.entities()) count += info.has(registry, e) ? 1 : 0;
        if (!count) continue;
        if (!components.empty()) components += ", ";
        components += std::string(info.name) + " x" + std::to_string(count);
    }
    std::string line = std::to_string(registry.size()) + " entities; components: " +
                       (components.empty() ? "none" : components);
    return line;
}

CLI::Validator wholeNumberAtLeastZero() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            errno = 0;
            char* end = nullptr;
            const long long value = std::strtoll(text.c_str(), &end, 10);
            if (text.empty() || *end != '\0' || errno == ERANGE || value < 0)
                return "expected a whole number >= 0, got \"" + text + "\"";
            return {};
        },
        "INT>=0");
}

} // namespace stepwise::cli
