#pragma once
// The rows of the Debug panel's contacts table: which contacts it lists and
// in what order. No ImGui here, so the order is unit-tested.

#include "stepwise/registry.hpp"
#include "stepwise/world.hpp"

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace stepwise::editor {

/// The table's columns, in the panel's order.
enum class ContactColumn { A, B, PointX, NormalY, Depth, NormalImpulse, TangentImpulse };

/// How the table is sorted: by one column, or in the step's order.
struct ContactSort {
    bool sorted = false;
    ContactColumn column = ContactColumn::A;
    bool descending = false;
};

/// Indices into `contacts` of those where either body's display name
/// contains `filter` ("" keeps all), in `sort`'s order. The sort is stable:
/// equal keys keep the step's order. Names compare as strings (`c10` before
/// `c2`); a plane or a removed body on side b sorts as "".
std::vector<std::size_t> contactRows(std::span<const ContactRecord> contacts, const Registry& registry,
                                     const std::string& filter, const ContactSort& sort);

} // namespace stepwise::editor
