// stepwise validate LEVEL: checks a level file and says what it contains and
// which systems it needs.

#include "cli/cli_common.hpp"
#include "cli/commands.hpp"

#include "stepwise/components.hpp"
#include "stepwise/world.hpp"

#include <CLI/CLI.hpp>

#include <iostream>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace stepwise::cli {

namespace {

/// Components that are valid but have no effect where they are: said, so
/// nothing in a level is ignored silently.
std::vector<std::string> ineffectiveComponents(const Scene& scene) {
    std::vector<std::string> notes;
    const Registry& r = scene.registry;
    const auto& order = r.entities();
    std::set<std::string> uncopied;  // templates noted as never copied, once each
    for (std::size_t i = 0; i < order.size(); ++i) {
        const Entity e = order[i];
        std::string label = "entity " + std::to_string(i);
        if (const Name* n = r.tryGet<Name>(e)) label += " (\"" + n->value + "\")";
        const bool isStatic = r.has<Static>(e) && r.tryGet<Static>(e)->value;
        const bool hasShape = r.has<Radius>(e) || r.has<Box>(e) || r.has<Polygon>(e) || r.has<Capsule>(e) ||
                               r.has<Chain>(e) || r.has<Plane>(e) || r.has<Shapes>(e);
        if (isStatic) {
            if (const Velocity* v = r.tryGet<Velocity>(e); v && (v->value.x != 0.0 || v->value.y != 0.0))
                notes.push_back(label + ": \"velocity\" on a static body has no effect (static bodies never move)");
            if (const AngularVelocity* w = r.tryGet<AngularVelocity>(e); w && w->value != 0.0)
                notes.push_back(label + ": \"angular_velocity\" on a static body has no effect");
            if (r.has<Drag>(e)) notes.push_back(label + ": \"drag\" on a static body has no effect (it never moves)");
            // A static attractor's mass sets its pull; otherwise a static
            // body's mass is infinite whatever the file says.
            if (r.has<Mass>(e) && !r.has<Attractor>(e))
                notes.push_back(label + ": \"mass\" on a static body has no effect (static mass is infinite)");
        }
        if (r.has<Kinematic>(e) && r.tryGet<Kinematic>(e)->value) {
            // As on a static body, an attractor's mass sets its pull.
            if (r.has<Mass>(e) && !r.has<Attractor>(e))
                notes.push_back(label + ": \"mass\" on a kinematic body has no effect (its mass is infinite)");
            if (r.has<Drag>(e))
                notes.push_back(label + ": \"drag\" on a kinematic body has no effect (only its velocity moves it)");
            if (r.has<Boid>(e))
                notes.push_back(label + ": \"boid\" on a kinematic body has no effect (only its velocity moves it)");
        }
        if (const Template* t = r.tryGet<Template>(e)) {
            if (const Velocity* v = r.tryGet<Velocity>(e); v && (v->value.x != 0.0 || v->value.y != 0.0))
                notes.push_back(label + ": \"velocity\" on a template body has no effect (each copy takes its "
                                        "emitter's velocity)");
            bool copied = false;
            r.each<Emitter>([&](Entity, const Emitter& em) { copied = copied || em.templateName == t->value; });
            if (!copied && uncopied.insert(t->value).second)
                notes.push_back(label + ": template \"" + t->value +
                                "\" has no emitter, so it is never copied (and never simulated)");
        }
        if (!hasShape) {
            if (r.has<Restitution>(e))
                notes.push_back(label + ": \"restitution\" has no effect: the entity has no shape, so it never collides");
            if (r.has<Friction>(e))
                notes.push_back(label + ": \"friction\" has no effect: the entity has no shape, so it never collides");
        }
    }
    return notes;
}

} // namespace

void addValidateCommand(CLI::App& app, int& exitCode) {
    auto level = std::make_shared<std::string>();
    CLI::App* cmd = app.add_subcommand("validate", "Check a level file; print a one-line summary or the error");
    cmd->add_option("LEVEL", *level, "Level file (JSON)")->required();
    cmd->callback([level, &exitCode] {
        std::optional<Scene> scene = loadLevelOrReport(*level);
        if (!scene) {
            exitCode = kExitBadInput;
            return;
        }
        std::string summary = *level + ": ok: " + sceneSummary(*scene);
        Result<World> world = World::build(*scene);
        if (world) {
            std::string systems;
            for (std::string_view s : world->activeSystems()) {
                if (!systems.empty()) systems += ", ";
                systems += s;
            }
            summary += "; systems: " + (systems.empty() ? std::string("none") : systems) + "; integrator " +
                       scene->world.integrator;
            std::cout << summary << "\n";
            // What substeps and iterations the contacts and joints run, and
            // why: a scene without them has nothing the choice affects.
            bool contactsOrJoints = false;
            for (std::string_view s : world->activeSystems())
                contactsOrJoints = contactsOrJoints || s == "collisions" || s == "joints";
            if (contactsOrJoints) std::cout << *level << ": " << world->settingsSummary() << "\n";
            for (const StiffnessHint& hint : world->stiffnessHints())
                std::cerr << *level << ": warning: " << hint.message() << "\n";
            if (const std::optional<PileHint> pile = world->pileHint())
                std::cerr << *level << ": warning: " << pile->message() << "\n";
            if (const std::optional<ContactStiffnessHint> stiffness = world->contactStiffnessHint())
                std::cerr << *level << ": warning: " << stiffness->message() << "\n";
            if (const std::optional<ImpactHint> impact = world->impactHint())
                std::cerr << *level << ": warning: " << impact->message() << "\n";
            if (const std::optional<JointLoopHint> loops = world->jointLoopHint())
                std::cerr << *level << ": warning: " << loops->message() << "\n";
            if (const std::optional<JointSupportHint> load = world->jointSupportHint())
                std::cerr << *level << ": warning: " << load->message() << "\n";
            if (const std::optional<DroppedImpulses> dropped = world->droppedImpulses())
                std::cerr << *level << ": warning: " << dropped->message() << "\n";
            for (const std::string& note : ineffectiveComponents(*scene))
                std::cerr << *level << ": warning: " << note << "\n";
        } else {
            // Every field is in its range, yet no step could take the level
            // (gravity that passes the speed limit in one step): `run` would
            // refuse it, so validation does too, in the same words.
            reportError(*level + ": cannot simulate: " + world.error());
            exitCode = kExitBadInput;
            return;
        }
        exitCode = kExitOk;
    });
}

} // namespace stepwise::cli
