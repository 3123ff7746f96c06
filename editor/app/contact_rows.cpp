#include "app/contact_rows.hpp"

#include "app/scene_edit.hpp"

#include <algorithm>
#include <optional>

namespace stepwise::editor {

std::vector<std::size_t> contactRows(std::span<const ContactRecord> contacts, const Registry& registry,
                                     const std::string& filter, const ContactSort& sort) {
    // Each body's name is built once and shared by the filter and the sort:
    // a settled 2,000-body pile has about 4,300 contacts, 8,600 ends, each
    // frame. Only live entities are kept (one per index), so the index is
    // the key; a plane or a removed body is "".
    // Sized once, so the references nameOf returns stay valid.
    std::size_t indices = 0;
    for (const ContactRecord& c : contacts)
        for (Entity e : {c.a, c.b})
            if (registry.alive(e)) indices = std::max(indices, std::size_t(e.index) + 1);
    std::vector<std::optional<std::string>> names(indices);
    const std::string none;
    const auto nameOf = [&](Entity e) -> const std::string& {
        if (!registry.alive(e)) return none;
        std::optional<std::string>& name = names[e.index];
        if (!name) name = displayName(registry, e);
        return *name;
    };
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
        // Each body's rank among the names: comparing names inside the row
        // sort compared about 50,000 strings a frame. Equal names share a
        // rank, so rows keep their order among them.
        const auto bodyOf = [&](std::size_t i) { return sort.column == ContactColumn::A ? contacts[i].a : contacts[i].b; };
        std::vector<Entity> bodies;
        for (std::size_t i : rows) bodies.push_back(bodyOf(i));
        const auto byIndex = [](Entity x, Entity y) { return x.index != y.index ? x.index < y.index : x.generation < y.generation; };
        std::sort(bodies.begin(), bodies.end(), byIndex);
        bodies.erase(std::unique(bodies.begin(), bodies.end()), bodies.end());
        std::vector<std::size_t> byName(bodies.size());  // positions in `bodies`, in name order
        for (std::size_t k = 0; k < bodies.size(); ++k) byName[k] = k;
        std::sort(byName.begin(), byName.end(), [&](std::size_t x, std::size_t y) { return nameOf(bodies[x]) < nameOf(bodies[y]); });
        std::vector<std::size_t> rankOf(bodies.size());
        for (std::size_t k = 0, rank = 0; k < byName.size(); ++k) {
            if (k > 0 && nameOf(bodies[byName[k]]) != nameOf(bodies[byName[k - 1]])) ++rank;
            rankOf[byName[k]] = rank;
        }
        std::vector<std::size_t> rowRank(contacts.size());
        for (std::size_t i : rows)
            rowRank[i] = rankOf[std::size_t(std::lower_bound(bodies.begin(), bodies.end(), bodyOf(i), byIndex) - bodies.begin())];
        std::stable_sort(rows.begin(), rows.end(), [&](std::size_t x, std::size_t y) {
            return sort.descending ? rowRank[y] < rowRank[x] : rowRank[x] < rowRank[y];
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
