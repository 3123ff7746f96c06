#pragma once
// Templates and emitters (docs/format.md, "Templates and emitters"): which
// entities are prefabs, which are an emitter's copies, and how a copy is
// made. The loader's checks, World::build and the emitters share these, so
// every part agrees on what a template holds.

#include "stepwise/components.hpp"
#include "stepwise/registry.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace stepwise::detail {

/// The template `e` belongs to, or nullptr: its own `template` component,
/// or, for a joint or spring without one, the template of its first end
/// (the loader refuses a joint or spring whose ends are in different
/// templates, or in one and outside it).
const std::string* templateOf(const Registry& reg, Entity e);

/// Whether `e` is part of a template (never simulated).
inline bool inTemplate(const Registry& reg, Entity e) { return templateOf(reg, e) != nullptr; }

/// Whether `e` is an emitter's copy: named "TEMPLATE#N" or "TEMPLATE#N/..."
/// with TEMPLATE the value of some entity's `template`. What the engine
/// chooses from the scene's structure (substeps) leaves copies out, so a
/// resumed run chooses what the run that saved it chose.
bool isEmittedCopy(const Registry& reg, Entity e);

/// An emitter without a shape: a point in the world, not a body.
inline bool pointEmitter(const Registry& reg, Entity e) {
    return reg.has<Emitter>(e) && !reg.has<Radius>(e) && !reg.has<Box>(e) && !reg.has<Polygon>(e) &&
           !reg.has<Capsule>(e) && !reg.has<Shapes>(e);
}

/// Left out of what the engine chooses from the scene's structure: the
/// copies a run has made so far (they come and go) and point emitters. A
/// template counts, standing for the copies its emitters will make.
inline bool outsideTheChoice(const Registry& reg, Entity e) {
    if (reg.count<Template>() == 0) return false;
    return pointEmitter(reg, e) || isEmittedCopy(reg, e);
}

/// `numbers` (oldest first) as Emitter::copies keeps them: empty when they
/// are the `alive` numbers up to `emitted`, so a template's only emitter
/// writes no list.
std::vector<int> storedCopyNumbers(const std::vector<int>& numbers, int emitted);

/// N when `name` is "TEMPLATE#N" or "TEMPLATE#N/..." (N written in at most
/// nine digits), else nothing.
std::optional<int> copyNumberIn(const std::string& name, const std::string& templateName);

/// The random turn of copy `number` of an emitter: a uniform angle in
/// [-spread, spread] from (world seed, emitter key, number) alone, so a
/// resumed run draws what the long run drew without carrying a generator.
double emitterTurn(int seed, std::uint64_t emitterKey, int number, double spread);

/// The emitter's key: a hash of its name (its place in the scene when it
/// has none), stable across save and load.
std::uint64_t emitterKey(const Registry& reg, Entity emitter, std::size_t sceneIndex);

} // namespace stepwise::detail
