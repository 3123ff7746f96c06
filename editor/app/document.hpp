#pragma once
/// \file document.hpp
/// The level being edited: the scene, where it lives on disk, whether it
/// has unsaved changes, and the crash-recovery autosave. Saving goes through
/// the engine's atomic writer, after the same relation checks the loader
/// runs, so the editor can never write a file the loader would refuse.

#include "stepwise/result.hpp"
#include "stepwise/scene.hpp"

#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace stepwise::editor {

/// A fresh level: default world, a floor, a few bodies (what "New" gives).
Scene makeNewScene();

class Document {
public:
    Scene scene;
    std::filesystem::path path;  ///< empty for an unsaved new level

    /// Replaces the document with `path`'s level. On failure nothing changes
    /// and the message is the loader's.
    Result<void> open(const std::filesystem::path& file);
    /// New level, no path.
    void reset(Scene fresh);
    /// Saves `what` (normally `scene`) to `file` (normally `path`).
    Result<void> saveAs(const Scene& what, const std::filesystem::path& file);

    bool dirty() const { return dirty_; }
    void markDirty() { dirty_ = true; }
    void markClean() { dirty_ = false; }
    /// "name.json" or "untitled".
    std::string title() const;

    /// Where the recovery copy of this document goes (one per document
    /// path, inside the config folder).
    std::filesystem::path recoveryPath(const std::filesystem::path& configDir) const;

private:
    bool dirty_ = false;
};

/// $XDG_CONFIG_HOME/stepwise, else $HOME/.config/stepwise, else ./.stepwise.
std::filesystem::path configDirectory();

/// What persists between runs: recent files and the font size. Kept in
/// CONFIG/settings.txt as "key value" lines (a format that tolerates being
/// hand-edited or truncated: unknown or bad lines are skipped).
/// The folder holding the running executable (from /proc/self/exe), or an
/// empty path when it cannot be read.
std::filesystem::path executableDirectory();

/// Where the level files are, whatever folder the editor was started from:
/// `levels/` beside the executable, one folder up (build/stepwise in a source
/// checkout), or `../share/stepwise/levels` (an installed copy); failing
/// those, `levels/` under `workingDir`, then `workingDir` itself. Absolute.
std::filesystem::path findLevelsDirectory(const std::filesystem::path& exeDir, const std::filesystem::path& workingDir);

/// The folder the Open and Save as dialogs start in: the open document's
/// folder, else `levelsDir`.
std::filesystem::path dialogFolder(const std::filesystem::path& documentPath, const std::filesystem::path& levelsDir);

/// The level files (*.json but the schema) in `folder`, sorted: the Open
/// dialog's list.
std::vector<std::string> levelFiles(const std::filesystem::path& folder);

/// Where Save as proposes to write: the document's own path; for an untitled
/// level, untitled.json (untitled_2.json, ... when taken) in the first folder
/// that exists and can be written of `workingDir`, the home folder and
/// `levelsDir` (never the program's own levels unless nothing else can be
/// written). Absolute.
std::filesystem::path saveAsSuggestion(const std::filesystem::path& documentPath,
                                       const std::filesystem::path& levelsDir,
                                       const std::filesystem::path& workingDir);

/// Where "Save simulation state as" proposes to write: NAME_state.json
/// (NAME_state_2.json, ... when taken) beside the open level NAME.json, or
/// untitled_state.json where Save as would put an untitled level. Absolute.
std::filesystem::path saveStateSuggestion(const std::filesystem::path& documentPath,
                                          const std::filesystem::path& levelsDir,
                                          const std::filesystem::path& workingDir);

/// The form a file takes in the recent list: absolute, with no "." or ".."
/// and symbolic links resolved, so one file is one entry.
std::string recentKey(const std::string& file);

/// True when saving to `target` would write over a file other than the
/// document's own (`documentPath`): Save as asks first.
bool replacesAnotherFile(const std::filesystem::path& target, const std::filesystem::path& documentPath);

struct Settings {
    std::vector<std::string> recentFiles;  ///< newest first, at most 10
    float fontSize = 0.0f;                 ///< pixels; 0 = from the display's DPI
    /// Panel rectangles as fractions (x, y, w, h) of the window, by panel
    /// name ("panel NAME x y w h" lines): the layout, whatever the window size.
    std::map<std::string, std::array<float, 4>> panels;
    void addRecent(const std::string& file);
    static Settings load(const std::filesystem::path& configDir);
    Result<void> save(const std::filesystem::path& configDir) const;
};

} // namespace stepwise::editor
