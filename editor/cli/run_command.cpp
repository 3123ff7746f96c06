// stepwise run LEVEL --steps N: steps the world headlessly and writes the
// resulting scene, an optional per-step energy trace and (with collisions)
// the contacts of every step.

#include "cli/cli_common.hpp"
#include "cli/commands.hpp"

#include "stepwise/components.hpp"
#include "stepwise/integrators.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>

namespace stepwise::cli {

namespace {

struct RunOptions {
    std::string level;
    long long steps = 0;
    std::optional<double> dt;
    std::optional<std::string> integrator;
    std::optional<std::string> out;
    std::optional<std::string> trace;
    std::optional<std::string> contacts;
};

std::string number(double v) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.17g", v);
    return buffer;
}

void appendTraceRow(std::string& csv, std::uint64_t step, const World& world) {
    const EnergyReport e = world.energy();
    csv += std::to_string(step) + "," + number(world.time()) + "," + number(e.kinetic) + "," + number(e.gravity) +
           "," + number(e.springs) + "," + number(e.attractors) + "," + number(e.potential()) + "," +
           number(e.total()) + "," + number(e.momentum.x) + "," + number(e.momentum.y) + "," +
           std::to_string(world.contacts().size()) + "\n";
}

/// How a contact names an entity: its name, or "entity N" (scene index).
std::string entityRef(const Scene& scene, Entity e) {
    const auto& order = scene.registry.entities();
    if (const Name* name = scene.registry.tryGet<Name>(e)) return name->value;
    const auto it = std::find(order.begin(), order.end(), e);
    return "entity " + std::to_string(it - order.begin());
}

std::string jsonString(const std::string& s) { return nlohmann::json(s).dump(); }

/// One JSON line: the step, the time and every contact of that step.
void appendContactLine(std::string& jsonl, std::uint64_t step, const World& world, const Scene& scene) {
    jsonl += "{\"step\": " + std::to_string(step) + ", \"time\": " + number(world.time()) + ", \"contacts\": [";
    bool first = true;
    for (const ContactRecord& c : world.contacts()) {
        if (!first) jsonl += ", ";
        first = false;
        jsonl += "{\"a\": " + jsonString(entityRef(scene, c.a)) + ", \"b\": " + jsonString(entityRef(scene, c.b)) +
                 ", \"point\": {\"x\": " + number(c.point.x) + ", \"y\": " + number(c.point.y) +
                 "}, \"normal\": {\"x\": " + number(c.normal.x + 0.0) + ", \"y\": " + number(c.normal.y + 0.0) +
                 "}, \"depth\": " + number(c.depth) + ", \"normal_impulse\": " + number(c.normalImpulse) +
                 ", \"tangent_impulse\": " + number(c.tangentImpulse) + "}";
    }
    jsonl += "]}\n";
}

int run(const RunOptions& options) {
    std::optional<Scene> scene = loadLevelOrReport(options.level);
    if (!scene) return kExitBadInput;
    if (options.dt) scene->world.dt = *options.dt;
    if (options.integrator) scene->world.integrator = *options.integrator;

    Result<World> built = World::build(*scene);
    if (!built) {
        reportError(options.level + ": cannot simulate: " + built.error());
        return kExitBadInput;
    }
    World& world = built.value();
    // Before playing: a pile the level's substeps cannot hold (stderr, so
    // the summary on stdout stays one line).
    if (const std::optional<PileHint> pile = world.pileHint())
        std::cerr << options.level << ": warning: " << pile->message() << "\n";

    std::string csv;
    if (options.trace) {
        csv = "step,time,kinetic,potential_gravity,potential_springs,potential_attractors,potential,total,"
              "momentum_x,momentum_y,contacts\n";
        appendTraceRow(csv, 0, world);
    }
    std::string jsonl;
    const auto start = std::chrono::steady_clock::now();
    std::optional<std::string> divergence;
    long long taken = 0;
    for (; taken < options.steps; ++taken) {
        if (Result<void> stepped = world.step(); !stepped) {
            divergence = stepped.error();
            break;
        }
        if (options.trace) appendTraceRow(csv, std::uint64_t(taken + 1), world);
        if (options.contacts) appendContactLine(jsonl, std::uint64_t(taken + 1), world, *scene);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    // The trace is written even after a divergence: it shows the run-up.
    if (options.trace) {
        if (Result<void> written = writeFileAtomically(*options.trace, csv); !written) {
            std::cerr << written.error() << "\n";
            return kExitBadInput;
        }
    }
    if (options.contacts) {
        if (Result<void> written = writeFileAtomically(*options.contacts, jsonl); !written) {
            std::cerr << written.error() << "\n";
            return kExitBadInput;
        }
    }
    if (divergence) {
        reportError(options.level + ": simulation diverged at " + *divergence + " (integrator " +
                    world.settings().integrator + ", dt " + number(world.settings().dt) + "); " +
                    (options.out ? "--out not written" : "no output written"));
        return kExitDiverged;
    }
    if (options.out) {
        world.writeBack(*scene);
        if (Result<void> saved = saveSceneFile(*scene, *options.out); !saved) {
            std::cerr << saved.error() << "\n";
            return kExitBadInput;
        }
    }
    const EnergyReport energy = world.energy();
    std::cout << options.level << ": ran " << taken << " steps of " << number(world.settings().dt) << " s ("
              << world.settings().substeps << " substep" << (world.settings().substeps == 1 ? "" : "s") << ") with "
              << world.settings().integrator << "; t = " << number(world.time()) << " s; " << world.bodyCount()
              << " dynamic bodies; total energy " << number(energy.total()) << " J; "
              << number(taken ? 1e3 * seconds / double(taken) : 0.0) << " ms/step";
    if (options.out) std::cout << "; wrote " << *options.out;
    if (options.trace) std::cout << "; trace " << *options.trace;
    std::cout << "\n";
    return kExitOk;
}

} // namespace

void addRunCommand(CLI::App& app, int& exitCode) {
    auto options = std::make_shared<RunOptions>();
    CLI::App* cmd = app.add_subcommand("run", "Step a level headlessly and write the resulting scene");
    cmd->add_option("LEVEL", options->level, "Level file (JSON)")->required();
    cmd->add_option("--steps", options->steps, "Number of steps to take")->required()->check(wholeNumberAtLeastZero());
    cmd->add_option("--dt", options->dt, "Seconds per step (overrides world.dt)")
        ->check(CLI::PositiveNumber & CLI::Range(0.0, 10.0));
    cmd->add_option("--integrator", options->integrator, "Integrator (overrides world.integrator)")
        ->check(CLI::IsMember(std::vector<std::string>(integratorNames().begin(), integratorNames().end())));
    cmd->add_option("--out", options->out, "Write the resulting scene here (atomic)");
    cmd->add_option("--trace", options->trace,
                    "Write a CSV row per step (step 0 is the initial state): time, energies, momentum, contacts");
    cmd->add_option("--contacts", options->contacts,
                    "Write one JSON line per step: the step, the time and every contact (entities, point, normal, "
                    "depth, normal and tangent impulse)");
    cmd->callback([options, &exitCode] { exitCode = run(*options); });
}

} // namespace stepwise::cli
