#include "overlay_set.hpp"

#include <string>

namespace stepwise::render {

const std::vector<std::pair<std::string_view, Overlay>>& overlayNames() {
    static const std::vector<std::pair<std::string_view, Overlay>> names = {
        {"velocity", Overlay::Velocity}, {"velocity-field", Overlay::VelocityField},
        {"force-field", Overlay::ForceField}, {"force", Overlay::Force}, {"net-force", Overlay::NetForce},
        {"contacts", Overlay::Contacts}, {"aabb", Overlay::Aabb},
        {"trails", Overlay::Trails}, {"joints", Overlay::Joints},
    };
    return names;
}

Result<OverlaySet> parseOverlayList(std::string_view list) {
    OverlaySet set;
    std::size_t start = 0;
    while (start <= list.size()) {
        std::size_t comma = list.find(',', start);
        if (comma == std::string_view::npos) comma = list.size();
        std::string_view item = list.substr(start, comma - start);
        while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
        while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
        if (item == "all") {
            for (const auto& [name, o] : overlayNames()) set.add(o);
        } else if (item == "none" || (item.empty() && list.find_first_not_of(' ') == std::string_view::npos)) {
        } else {
            bool found = false;
            for (const auto& [name, o] : overlayNames())
                if (name == item) { set.add(o); found = true; }
            if (!found) {
                std::string known;
                for (const auto& [name, o] : overlayNames()) known += std::string(known.empty() ? "" : ", ") + std::string(name);
                return Error{"unknown overlay \"" + std::string(item) + "\"; known overlays: " + known + ", all, none"};
            }
        }
        start = comma + 1;
    }
    return set;
}

} // namespace stepwise::render
