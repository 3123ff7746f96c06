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
#include "stepwise/scene.hpp"

#include <span>
#include <string_view>
#include <vector>

namespace stepwise {

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

    /// True when `settings` holds "not given" for an optional field.
    bool isUnset(const WorldSettings& settings) const;
};

/// The table, in the order settings are written to files.
std::span<const WorldFieldInfo> worldFieldTable();

/// Row for `key`, or nullptr.
const WorldFieldInfo* findWorldField(std::string_view key);

/// Every key, in table order.
std::vector<std::string_view> worldFieldNames();

} // namespace stepwise
