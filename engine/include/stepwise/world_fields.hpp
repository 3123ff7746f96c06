#pragma once
/// \file world_fields.hpp
/// The one table of world settings (the `world` object of a level file):
/// JSON key, kind, valid range, unit, description and whether the key may be
/// left out for the engine to choose. The loader (readWorld), the saver, the
/// JSON schema and the editor's World panel all read it, as they read the
/// component table for components. A setting's default is the value in a
/// default-constructed WorldSettings (scene.hpp), read through the table's
/// `address`, so it is written in one place.

#include "stepwise/component_table.hpp"
#include "stepwise/result.hpp"
#include "stepwise/scene.hpp"

#include <optional>
#include <span>
#include <string_view>
#include <vector>

namespace stepwise {

/// The most substeps (and solver iterations) a level may give: far past
/// any useful level, it keeps a typo (1e9 substeps) from freezing a run.
inline constexpr int kMaxLevelSubsteps = 1000;

/// dopri5's smallest internal step, as a fraction of the frame (dt): below
/// it the step is refused as one that cannot meet the tolerance.
inline constexpr double kSmallestAdaptiveStep = 1e-12;

struct WorldFieldInfo {
    /// key, kind, range, unit, description; `address` points into a
    /// WorldSettings.
    FieldInfo field;
    /// The file may leave the key out and the engine then chooses (substeps,
    /// solver_iterations, adaptive_step): in memory 0 means "not given", a
    /// save writes no key, and the World panel shows "auto". When given, the
    /// value must be in `field.range`. OptionalNumber fields are optional by
    /// their kind (nullopt = not given).
    bool optional = false;
    /// The range's max only keeps a typo in a file or an edit (dt 1e9) from
    /// freezing a run: the loader and the World panel hold to it, but a
    /// scene made in code may go past it (worldSettingsProblem checks the
    /// rest of the range).
    bool maxGuardsInputOnly = false;

    /// True when `settings` holds "not given" for an optional field.
    bool isUnset(const WorldSettings& settings) const;
};

/// The table, in the order settings are written to files.
std::span<const WorldFieldInfo> worldFieldTable();

/// Row for `key`, or nullptr.
const WorldFieldInfo* findWorldField(std::string_view key);

/// Every key, in table order.
std::vector<std::string_view> worldFieldNames();

/// The first setting, in table order, whose value its row refuses
/// (fieldValueProblem), as "world.KEY: expected ..., got ..." (the words the
/// loader writes after /world/KEY and the World panel after "world."), or
/// nothing. Optional settings left unset are not checked, nor the max of a
/// row that guards input only. World::build checks with it, so a scene made
/// in code is held to the file's ranges but for those caps.
std::optional<Error> worldSettingsProblem(const WorldSettings& settings);
/// adaptive_step against dt: 0 (none yet) or above kSmallestAdaptiveStep
/// dt, or dopri5 refuses its first step. The loader checks it once the
/// world is read; worldSettingsProblem includes it.
std::optional<Error> adaptiveStepProblem(const WorldSettings& settings);

} // namespace stepwise
