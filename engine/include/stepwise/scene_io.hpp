#pragma once
/// \file scene_io.hpp
/// Reading and writing level files (docs/format.md). Everything is
/// driven by the component table. A bad file is refused whole with one
/// message; saving is atomic.

#include "stepwise/result.hpp"
#include "stepwise/scene.hpp"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace stepwise {

/// Documented limits of the loader (docs/format.md, "Limits"). Past them a file is
/// refused with a message instead of exhausting memory.
struct LoadLimits {
    std::uintmax_t maxFileBytes = 256ull << 20;  ///< 256 MiB of JSON text
    std::size_t maxEntities = 1'000'000;
    int maxDepth = 16;                            ///< JSON nesting; real levels use 4
    /// Every JSON value counts (numbers, strings, true/false/null, objects,
    /// arrays, at any depth): the DOM costs 16 to about 120 bytes per value,
    /// so this bounds the loader's memory for every shape of file. A level
    /// uses about 14 per entity (name, position, velocity, mass, radius,
    /// colour), so the entity limit is reached first by real levels.
    std::size_t maxValues = 20'000'000;
    /// Values inside one entity (its components and their fields).
    std::size_t maxValuesPerEntity = 100'000;
    /// Keys in one JSON object. The DOM keeps an object's keys in file
    /// order and finds one by searching them, so reading n keys costs n^2 / 2
    /// comparisons; a level's largest object (an entity, the world) has
    /// about 20 keys.
    std::size_t maxKeysPerObject = 256;
};

/// Parses level text. `sourceName` prefixes every message ("levels/a.json").
/// Messages: "NAME:LINE:COL: error: ..." for JSON syntax, "NAME: error:
/// /json/pointer: ..." for wrong shape or value.
Result<Scene> parseScene(std::string_view text, std::string_view sourceName,
                         const LoadLimits& limits = {});

/// Reads and parses a level file.
Result<Scene> loadSceneFile(const std::filesystem::path& path, const LoadLimits& limits = {});

/// The level as file text: entities in scene order, components in table
/// order, numbers in the shortest form that reads back to the same double.
/// load -> save -> load -> save gives identical bytes.
std::string sceneToJsonText(const Scene& scene);

/// Whether `path` can be written by writeFileAtomically: its folder exists,
/// is a folder and the user may create files in it, and an existing target
/// is a regular file the user may write (a read-only file is refused even
/// though the rename would replace it). "" or "PATH: error: cannot write:
/// REASON". Checked by every save, and by the command line for every output
/// before any work.
std::string checkWritableTarget(const std::filesystem::path& path);

/// Where a write to `path` lands: `path` itself, or, for a symbolic link
/// (a dangling one included), the file it finally points at. Outputs are
/// written through links, so a linked file stays linked and its target gets
/// the new bytes; the same-file checks compare the targets.
std::filesystem::path resolveOutputPath(const std::filesystem::path& path);

/// A file written in pieces and put in place atomically at the end (a long
/// run's trace: memory stays flat however many steps). The bytes go to a
/// hidden temporary in the target's folder; commit() does fsync, rename
/// over the target and fsync of the folder. Destroyed without commit() (an
/// error, a divergence, Ctrl-C), the temporary is removed and the target is
/// untouched.
class StreamedFileWriter {
public:
    /// Checks the target (checkWritableTarget) and creates the temporary.
    static Result<StreamedFileWriter> open(const std::filesystem::path& path);
    StreamedFileWriter(StreamedFileWriter&& other) noexcept;
    StreamedFileWriter& operator=(StreamedFileWriter&& other) noexcept;
    ~StreamedFileWriter();

    /// Appends; written to the temporary in blocks of 1 MiB.
    Result<void> write(std::string_view bytes);
    /// Writes the rest, fsyncs and closes the temporary (not yet in place).
    Result<void> finish();
    /// finish() if not done, then renames the temporary over the target.
    Result<void> commit();
    /// Removes the temporary; the target stays as it was.
    void discard();

private:
    StreamedFileWriter() = default;
    Result<void> writeAll(std::string_view bytes);
    Result<void> fail(const char* what, int err);
    std::string name_, tmpPath_;
    std::filesystem::path folder_;
    std::string buffer_;
    int fd_ = -1;
    bool finished_ = false;
    void* slot_ = nullptr;  ///< where removeUnfinishedTemporaries() finds tmpPath_
};

/// Removes the hidden temporary of every StreamedFileWriter that is neither
/// committed nor discarded. Async-signal-safe (unlink only, over a fixed
/// table): an interrupt handler calls it before _exit, so that every output
/// is either as it was or complete and no temporary is left.
void removeUnfinishedTemporaries() noexcept;

/// Writes `bytes` to `path` atomically: a temporary file in the same folder,
/// fsync, rename over the target, fsync of the folder. On any failure the old
/// file is untouched and no temporary is left behind.
Result<void> writeFileAtomically(const std::filesystem::path& path, std::string_view bytes);

/// sceneToJsonText + writeFileAtomically. A save killed outright (SIGKILL,
/// power loss) leaves the old file and its hidden `.NAME.tmp-XXXXXX`; a
/// later successful save of the same file removes such temporaries once they
/// are over an hour old (younger ones may be another process's save in
/// progress).
Result<void> saveSceneFile(const Scene& scene, const std::filesystem::path& path);

/// Checks the relations between entities that no single component can check:
/// unique names, spring ends that exist and are bodies, one shape per body.
/// Nothing when they hold, else an Error "/json/pointer: message".
/// parseScene runs it; the editor runs it before saving.
std::optional<Error> checkSceneRelations(const Scene& scene);

struct Joint;
/// Fills what a joint takes from the bodies' poses as they are now (the
/// loader runs it on every joint; the editor's Joint tool too): an `anchor`
/// becomes `local_a` / `local_b` (and is cleared), a missing
/// `reference_angle` becomes b's angle minus a's (hinge, slider, weld), a
/// missing `length` the anchors' distance (distance, rope). The ends must
/// pass checkSceneRelations. A refusal's `where` is the joint's field.
std::optional<Error> completeJoint(const Registry& registry, Joint& joint);

} // namespace stepwise

namespace stepwise {

/// JSON Schema (2020-12) of the level format, generated from the component
/// table (levels/scene.schema.json is this text; a test keeps them equal).
std::string sceneJsonSchema();

} // namespace stepwise
