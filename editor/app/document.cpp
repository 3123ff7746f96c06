#include "app/document.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/scene_io.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <sstream>

namespace stepwise::editor {

Scene makeNewScene() {
    Scene s;
    s.view = View{{0.0, 3.0}, 40.0};
    addPlane(s, {0.0, 0.0}, {0.0, 1.0});
    return s;
}

Result<void> Document::open(const std::filesystem::path& file) {
    Result<Scene> loaded = loadSceneFile(file);
    if (!loaded) return Error{loaded.error()};
    scene = std::move(*loaded);
    path = file;
    dirty_ = false;
    return {};
}

void Document::reset(Scene fresh) {
    scene = std::move(fresh);
    path.clear();
    dirty_ = false;
}

Result<void> Document::saveAs(const Scene& what, const std::filesystem::path& file) {
    if (file.empty()) return Error{"no file name given"};
    if (const std::optional<Error> problem = checkSceneRelations(what))
        return Error{"not saved: the level is not valid: " + problem->message};
    Result<void> saved = saveSceneFile(what, file);
    if (!saved) return saved;
    path = file;
    dirty_ = false;
    return {};
}

std::string Document::title() const { return path.empty() ? std::string("untitled") : path.filename().string(); }

std::filesystem::path Document::recoveryPath(const std::filesystem::path& configDir) const {
    // Hash of the absolute path: two editors on two levels do not share a
    // recovery file. std::hash of a string is stable within one library build,
    // which is all a crash-recovery file needs.
    std::error_code ec;
    const std::string key = path.empty() ? std::string("untitled") : std::filesystem::absolute(path, ec).string();
    std::ostringstream name;
    name << "recovery-" << std::hex << (std::hash<std::string>{}(key) & 0xFFFFFFFFull) << ".json";
    return configDir / "recovery" / name.str();
}

std::filesystem::path configDirectory() {
    if (const char* xdg = std::getenv("XDG_CONFIG_HOME"); xdg && *xdg) return std::filesystem::path(xdg) / "stepwise";
    if (const char* home = std::getenv("HOME"); home && *home)
        return std::filesystem::path(home) / ".config" / "stepwise";
    return std::filesystem::path(".stepwise");
}

std::filesystem::path executableDirectory() {
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    return ec ? std::filesystem::path() : exe.parent_path();
}

std::filesystem::path findLevelsDirectory(const std::filesystem::path& exeDir, const std::filesystem::path& workingDir) {
    std::error_code ec;
    std::vector<std::filesystem::path> candidates;
    if (!exeDir.empty())
        for (const char* relative : {"levels", "../levels", "../share/stepwise/levels"})
            candidates.push_back(exeDir / relative);
    candidates.push_back(workingDir / "levels");
    for (const std::filesystem::path& c : candidates)
        if (std::filesystem::is_directory(c, ec)) return std::filesystem::weakly_canonical(c, ec);
    return std::filesystem::absolute(workingDir, ec);
}

std::filesystem::path dialogFolder(const std::filesystem::path& documentPath, const std::filesystem::path& levelsDir) {
    std::error_code ec;
    if (!documentPath.empty()) {
        const std::filesystem::path folder = std::filesystem::absolute(documentPath, ec).parent_path();
        if (std::filesystem::is_directory(folder, ec)) return folder;
    }
    return levelsDir;
}

std::vector<std::string> levelFiles(const std::filesystem::path& folder) {
    std::vector<std::string> out;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(folder, ec))
        if (entry.path().extension() == ".json" && entry.path().filename() != "scene.schema.json")
            out.push_back(entry.path().string());
    std::sort(out.begin(), out.end());
    return out;
}

namespace {

/// The first writable folder of `folders`, else the last one; absolute.
std::filesystem::path writableFolder(const std::vector<std::filesystem::path>& folders) {
    std::error_code ec;
    for (const std::filesystem::path& f : folders)
        if (!f.empty() && std::filesystem::is_directory(f, ec) && ::access(f.c_str(), W_OK) == 0)
            return std::filesystem::absolute(f, ec);
    return folders.empty() ? std::filesystem::path() : std::filesystem::absolute(folders.back(), ec);
}

/// `folder`/`stem`.json, or `stem`_2.json, _3 ... when that file exists: a
/// proposal never names a file that Save would replace.
std::filesystem::path freeName(const std::filesystem::path& folder, const std::string& stem) {
    std::error_code ec;
    std::filesystem::path p = folder / (stem + ".json");
    for (int n = 2; std::filesystem::exists(p, ec) && n < 1000; ++n) p = folder / (stem + "_" + std::to_string(n) + ".json");
    return p;
}

/// Where a new file goes: the open level's folder, else (an untitled level)
/// the working folder, the home folder or the levels folder, the first that
/// can be written.
std::filesystem::path proposalFolder(const std::filesystem::path& documentPath, const std::filesystem::path& levelsDir,
                                     const std::filesystem::path& workingDir) {
    std::error_code ec;
    std::vector<std::filesystem::path> folders;
    if (!documentPath.empty()) folders.push_back(std::filesystem::absolute(documentPath, ec).parent_path());
    folders.push_back(workingDir);
    if (const char* home = std::getenv("HOME"); home && *home) folders.emplace_back(home);
    folders.push_back(levelsDir);
    return writableFolder(folders);
}

} // namespace

std::filesystem::path saveAsSuggestion(const std::filesystem::path& documentPath,
                                       const std::filesystem::path& levelsDir,
                                       const std::filesystem::path& workingDir) {
    std::error_code ec;
    if (!documentPath.empty()) return std::filesystem::absolute(documentPath, ec);
    return freeName(proposalFolder(documentPath, levelsDir, workingDir), "untitled");
}

std::filesystem::path saveStateSuggestion(const std::filesystem::path& documentPath,
                                          const std::filesystem::path& levelsDir,
                                          const std::filesystem::path& workingDir) {
    const std::string stem = documentPath.empty() ? std::string("untitled") : documentPath.stem().string();
    return freeName(proposalFolder(documentPath, levelsDir, workingDir), stem + "_state");
}

bool replacesAnotherFile(const std::filesystem::path& target, const std::filesystem::path& documentPath) {
    std::error_code ec;
    if (!std::filesystem::exists(target, ec)) return false;
    return documentPath.empty() || !std::filesystem::equivalent(target, documentPath, ec);
}

std::string recentKey(const std::string& file) {
    // One entry per file, however it was named: "levels/a.json" and
    // "/home/x/levels/a.json" are the same file.
    std::error_code ec;
    const std::filesystem::path p = std::filesystem::weakly_canonical(std::filesystem::absolute(file, ec), ec);
    return ec || p.empty() ? file : p.string();
}

void Settings::addRecent(const std::string& file) {
    const std::string key = recentKey(file);
    std::erase_if(recentFiles, [&](const std::string& f) { return recentKey(f) == key; });
    recentFiles.insert(recentFiles.begin(), key);
    if (recentFiles.size() > 10) recentFiles.resize(10);
}

Settings Settings::load(const std::filesystem::path& configDir) {
    Settings s;
    std::ifstream in(configDir / "settings.txt");
    for (std::string line; std::getline(in, line);) {
        const auto space = line.find(' ');
        if (space == std::string::npos) continue;
        const std::string key = line.substr(0, space), value = line.substr(space + 1);
        if (key == "recent" && !value.empty() && s.recentFiles.size() < 10 &&
            std::none_of(s.recentFiles.begin(), s.recentFiles.end(),
                         [&](const std::string& f) { return recentKey(f) == recentKey(value); }))
            s.recentFiles.push_back(recentKey(value));
        else if (key == "font_size") {
            char* end = nullptr;
            const float f = std::strtof(value.c_str(), &end);
            if (end != value.c_str() && f >= 6.0f && f <= 64.0f) s.fontSize = f;
        } else if (key == "panel") {
            // A damaged line is skipped: the panel then starts at its default.
            std::istringstream fields(value);
            std::string name;
            std::array<float, 4> r{};
            if (fields >> name >> r[0] >> r[1] >> r[2] >> r[3] && r[2] > 0.0f && r[3] > 0.0f && r[2] <= 1.0f &&
                r[3] <= 1.0f && r[0] >= -1.0f && r[0] <= 1.0f && r[1] >= -1.0f && r[1] <= 1.0f)
                s.panels[name] = r;
        }
    }
    return s;
}

Result<void> Settings::save(const std::filesystem::path& configDir) const {
    std::error_code ec;
    std::filesystem::create_directories(configDir, ec);
    if (ec) return Error{"cannot create " + configDir.string() + ": " + ec.message()};
    std::string text;
    for (const std::string& f : recentFiles) text += "recent " + f + "\n";
    if (fontSize > 0.0f) text += "font_size " + std::to_string(fontSize) + "\n";
    for (const auto& [name, r] : panels) {
        std::ostringstream line;
        line.precision(6);
        line << "panel " << name << ' ' << r[0] << ' ' << r[1] << ' ' << r[2] << ' ' << r[3] << '\n';
        text += line.str();
    }
    return writeFileAtomically(configDir / "settings.txt", text);
}

} // namespace stepwise::editor
