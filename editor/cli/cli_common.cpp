#include "cli/cli_common.hpp"

#include "stepwise/component_table.hpp"
#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <tuple>

#include <sys/stat.h>

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
        // Compound bodies: how many shapes they hold between them.
        if (info.name == "shapes") {
            std::size_t shapes = 0;
            for (Entity e : registry.entities())
                if (const Shapes* s = registry.tryGet<Shapes>(e)) shapes += s->items.size();
            components += " (" + std::to_string(shapes) + " shapes)";
        }
    }
    std::string line = std::to_string(registry.size()) + " entities; components: " +
                       (components.empty() ? "none" : components);
    return line;
}

namespace {

/// Device and inode of the file `path` names; for a file not there yet,
/// those of its folder plus its name. False when the folder is missing too.
bool fileIdentity(const std::string& given, std::tuple<dev_t, ino_t, std::string>& id) {
    struct stat info {};
    if (::stat(given.c_str(), &info) == 0) {
        id = {info.st_dev, info.st_ino, std::string()};
        return true;
    }
    // Not there yet: where a write would create it (through a dangling link).
    const std::filesystem::path p = resolveOutputPath(given);
    const std::filesystem::path folder = p.has_parent_path() ? p.parent_path() : std::filesystem::path(".");
    if (::stat(folder.c_str(), &info) != 0) return false;
    id = {info.st_dev, info.st_ino, p.filename().string()};
    return true;
}

} // namespace

Result<void> checkOutputs(const std::vector<std::string>& inputs, const std::vector<OutputFile>& outputs) {
    using Identity = std::tuple<dev_t, ino_t, std::string>;
    std::vector<std::pair<Identity, std::string>> inputIds;
    for (const std::string& in : inputs) {
        Identity id;
        if (fileIdentity(in, id)) inputIds.emplace_back(id, in);
    }
    // By identity, so that render's up to 100,000 frames are checked in
    // n log n, not n^2.
    std::map<Identity, const OutputFile*> seen;
    for (const OutputFile& out : outputs) {
        // The saver's own message, as a failed save prints it.
        if (std::string problem = checkWritableTarget(out.path); !problem.empty())
            return Error{problem, "", ErrorKind::Io};
        Identity id;
        if (!fileIdentity(out.path, id)) continue;  // checkWritableTarget said why already
        for (const auto& [inputId, name] : inputIds)
            if (inputId == id)
                return Error{out.path + " is the input " + name + "; refusing to replace it (give the output another name)",
                             out.option};
        if (const auto other = seen.find(id); other != seen.end())
            return Error{out.path + " is the same file as " + other->second->option + " " + other->second->path +
                             "; give each output its own file",
                         out.option};
        seen.emplace(id, &out);
    }
    return {};
}

void reportOutputProblem(const Error& problem) {
    if (problem.kind == ErrorKind::Io) std::cerr << problem.message << "\n";
    else reportError(problem.text());
}

} // namespace stepwise::cli
