#pragma once
/// \file scene_io.hpp
/// Reading and writing level files (shared/SCENE_FORMAT.md). Everything is
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

/// Documented limits of the loader (README "Limits"). Past them a file is
/// refused with a message instead of exhausting memory.
struct LoadLimits {
    std::uintmax_t maxFileBytes = 256ull << 20;  ///< 256 MiB of JSON text
    std::size_t maxEntities = 1'000'000;
    int maxDepth = 16;                            ///< JSON nesting; real levels use 4
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
/// Returns "" or "/json/pointer: message". parseScene runs it; the editor
/// runs it before saving.
std::string checkSceneRelations(const Scene& scene);

struct Joint;
/// Fills what a joint takes from the bodies' poses as they are now (the
/// loader runs it on every joint; the editor's Joint tool too): an `anchor`
/// becomes `local_a` / `local_b` (and is cleared), a missing
/// `reference_angle` becomes b's angle minus a's (hinge, slider, weld), a
/// missing `length` the anchors' distance (distance, rope). The ends must
/// pass checkSceneRelations. Returns "" or "FIELD: message".
std::string completeJoint(const Registry& registry, Joint& joint);

} // namespace stepwise

namespace stepwise {

/// JSON Schema (2020-12) of the level format, generated from the component
/// table (levels/scene.schema.json is this text; a test keeps them equal).
std::string sceneJsonSchema();

} // namespace stepwise
