#pragma once
/// \file entity.hpp
/// Entity handles: an index into the registry's slot table plus the
/// generation that slot had when the handle was made. Destroying an entity
/// bumps the slot's generation, so every older handle to it becomes stale and
/// is detected (never dereferenced) — the scheme of Box2D's b2BodyId and
/// EnTT's index+version.

#include <cstdint>
#include <functional>

namespace stepwise {

struct Entity {
    static constexpr std::uint32_t kInvalidIndex = 0xFFFFFFFFu;
    std::uint32_t index = kInvalidIndex;
    std::uint32_t generation = 0;

    /// True for the default handle, which was never issued by a Registry
    /// (index == kInvalidIndex). False says only that the handle was issued
    /// once, not that its entity is still alive: ask the Registry for that.
    constexpr bool isNull() const { return index == kInvalidIndex; }
    friend constexpr bool operator==(Entity, Entity) = default;
};

} // namespace stepwise

template <>
struct std::hash<stepwise::Entity> {
    std::size_t operator()(stepwise::Entity e) const noexcept {
        return (std::size_t(e.generation) << 32) ^ e.index;
    }
};
