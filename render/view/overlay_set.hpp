#pragma once
/// \file overlay_set.hpp
/// Which debug views a frame shows. Part of the view library (render/view):
/// what the renderer draws and the editor model holds, with no GL, so the
/// editor model (editor/app) needs no renderer. The namespace stays
/// `render` because these types are the renderer's input vocabulary.

#include "stepwise/result.hpp"

#include <cstdint>
#include <string_view>
#include <utility>
#include <vector>

namespace stepwise::render {

/// Debug views, each switched separately.
enum class Overlay : std::uint32_t {
    Velocity = 1u << 0,       ///< an arrow per body
    VelocityField = 1u << 1,  ///< kernel-weighted velocity of nearby bodies on a grid
    ForceField = 1u << 2,     ///< World::probeForce on a grid (needs a World)
    Force = 1u << 3,          ///< applied force per body (gravity, springs, ...), World::bodyForces (needs a World)
    Contacts = 1u << 4,       ///< World::contacts(): points, normals, impulses
    Aabb = 1u << 5,           ///< bounding boxes and the occupied cells of a uniform grid
    Trails = 1u << 6,         ///< positions over the last N recorded steps
    Joints = 1u << 7,         ///< World::joints(): reaction force at each joint's anchor
    NetForce = 1u << 8,       ///< net force per body over the last step, contacts included, World::netForces
};

struct OverlaySet {
    std::uint32_t bits = 0;
    bool has(Overlay o) const { return (bits & std::uint32_t(o)) != 0; }
    void add(Overlay o) { bits |= std::uint32_t(o); }
    bool needsWorld() const {
        return has(Overlay::ForceField) || has(Overlay::Force) || has(Overlay::NetForce) || has(Overlay::Contacts) ||
               has(Overlay::Joints);
    }
};

/// Command-line names, in drawing-legend order: "velocity", "velocity-field",
/// "force-field", "force" (applied), "net-force", "contacts", "aabb",
/// "trails", "joints".
const std::vector<std::pair<std::string_view, Overlay>>& overlayNames();

/// Parses "velocity,force-field" (or "all", or "" for none). The error names
/// the unknown entry and lists the known ones.
Result<OverlaySet> parseOverlayList(std::string_view list);

} // namespace stepwise::render
