#pragma once
// Builds a FieldInfo from a pointer to member, for the component table and
// the world-settings table: the kind follows from the member's C++ type, and
// `address` finds the member inside the struct.

#include "stepwise/component_table.hpp"
#include "stepwise/components.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

namespace stepwise::detail {

template <class>
struct MemberTraits;
template <class C, class M>
struct MemberTraits<M C::*> {
    using Class = C;
    using Type = M;
};

template <auto Member>
void* addressOf(void* component) {
    using C = typename MemberTraits<decltype(Member)>::Class;
    return &(static_cast<C*>(component)->*Member);
}

/// Field kind follows from the member's C++ type, so the table cannot say
/// "Number" for a Vec2.
template <class M>
constexpr FieldKind kindOf() {
    if constexpr (std::is_same_v<M, double>) return FieldKind::Number;
    else if constexpr (std::is_same_v<M, int>) return FieldKind::Integer;
    else if constexpr (std::is_same_v<M, std::uint32_t>) return FieldKind::Bits;
    else if constexpr (std::is_same_v<M, std::optional<double>>) return FieldKind::OptionalNumber;
    else if constexpr (std::is_same_v<M, Vec2>) return FieldKind::Vector;
    else if constexpr (std::is_same_v<M, std::optional<Vec2>>) return FieldKind::OptionalVector;
    else if constexpr (std::is_same_v<M, Rgb>) return FieldKind::Color;
    else if constexpr (std::is_same_v<M, bool>) return FieldKind::Bool;
    else if constexpr (std::is_same_v<M, Entity>) return FieldKind::EntityRef;
    else if constexpr (std::is_same_v<M, std::vector<Vec2>>) return FieldKind::VectorList;
    else if constexpr (std::is_same_v<M, std::vector<CompoundShape>>) return FieldKind::ShapeList;
    else if constexpr (std::is_same_v<M, std::vector<int>>) return FieldKind::IntegerList;
    else {
        static_assert(std::is_same_v<M, std::string>, "unsupported field type");
        return FieldKind::String;
    }
}

template <auto Member>
FieldInfo makeField(std::string_view key, NumberRange range, std::string_view unit, std::string_view description) {
    using M = typename MemberTraits<decltype(Member)>::Type;
    return FieldInfo{key, kindOf<M>(), range, unit, description, &addressOf<Member>};
}

} // namespace stepwise::detail
