#include "app/contact_rows.hpp"

#include "app/scene_edit.hpp"

#include <algorithm>

namespace stepwise::editor {

std::vector<std::size_t> contactRows(std::span<const ContactRecord> contacts, const Registry& registry,
                                     const std::string& filter, const ContactSort& sort) {
    const auto nameOf = [&](Entity e) { return registry.alive(e) ? displayName(registry, e) : std::string(); };
    std::vector<std::size_t> rows;
    rows.reserve(contacts.size());
    for (std::size_t i = 0; i < contacts.size(); ++i) {
        const ContactRecord& c = contacts[i];
        if (!filter.empty() && nameOf(c.a).find(filter) == std::string::npos &&
            nameOf(c.b).find(filter) == std::string::npos)
            continue;
        rows.push_back(i);
    }
    if (!sort.sorted) return rows;
    if (sort.column == ContactColumn::A || sort.column == ContactColumn::B) {
        // Each name once, not twice per comparison: a settled 2,000-body
        // pile has about 4,300 contacts, and building both names inside the
        // comparison made about 100,000 strings a frame (about 1.5 ms of the
        // editor's thread).
        std::vector<std::string> names(contacts.size());
        for (std::size_t i : rows) names[i] = nameOf(sort.column == ContactColumn::A ? contacts[i].a : contacts[i].b);
        std::stable_sort(rows.begin(), rows.end(), [&](std::size_t x, std::size_t y) {
            return sort.descending ? names[y] < names[x] : names[x] < names[y];
        });
        return rows;
    }
    const auto key = [&](std::size_t i) {
        const ContactRecord& c = contacts[i];
        switch (sort.column) {
        case ContactColumn::PointX: return c.point.x;
        case ContactColumn::NormalY: return c.normal.y;
        case ContactColumn::Depth: return c.depth;
        case ContactColumn::NormalImpulse: return c.normalImpulse;
        case ContactColumn::TangentImpulse: return c.tangentImpulse;
        case ContactColumn::A:
        case ContactColumn::B: break;
        }
        return 0.0;
    };
    std::stable_sort(rows.begin(), rows.end(), [&](std::size_t x, std::size_t y) {
        return sort.descending ? key(y) < key(x) : key(x) < key(y);
    });
    return rows;
}

} // namespace stepwise::editor
