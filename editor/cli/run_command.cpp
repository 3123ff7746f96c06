// stepwise run LEVEL --steps N: steps the world headlessly and writes the
// resulting scene, an optional per-step energy trace and (with collisions)
// the contacts of every step.

#include "cli/cli_common.hpp"
#include "cli/interrupts.hpp"
#include "cli/option_checks.hpp"
#include "cli/commands.hpp"

#include "stepwise/components.hpp"
#include "stepwise/integrators.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <vector>

#include <sys/statvfs.h>
#include <unistd.h>

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
/// An entity's name, or "entity N". An emitter's copies are named by the
/// World (`world`): the scene holds them only once the run is written back.
std::string entityRef(const Scene& scene, Entity e, const World* world = nullptr) {
    const auto& order = scene.registry.entities();
    if (const Name* name = scene.registry.tryGet<Name>(e)) return name->value;
    if (const std::string* copy = world ? world->copyName(e) : nullptr) return *copy;
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
        jsonl += "{\"a\": " + jsonString(entityRef(scene, c.a, &world)) +
                 ", \"b\": " + jsonString(entityRef(scene, c.b, &world)) +
                 ", \"point\": {\"x\": " + number(c.point.x) + ", \"y\": " + number(c.point.y) +
                 "}, \"normal\": {\"x\": " + number(c.normal.x + 0.0) + ", \"y\": " + number(c.normal.y + 0.0) +
                 "}, \"depth\": " + number(c.depth) + ", \"normal_impulse\": " + number(c.normalImpulse) +
                 ", \"tangent_impulse\": " + number(c.tangentImpulse) + "}";
    }
    jsonl += "]";
    // Joint lines only for a level with joints, so other levels' output is
    // unchanged: reaction force and torque on b (a feels the opposite),
    // world anchors and their separation, relative angle.
    if (!world.joints().empty()) {
        jsonl += ", \"joints\": [";
        first = true;
        for (const JointRecord& j : world.joints()) {
            if (!first) jsonl += ", ";
            first = false;
            const auto vector = [](Vec2 v) {
                return "{\"x\": " + number(v.x + 0.0) + ", \"y\": " + number(v.y + 0.0) + "}";
            };
            jsonl += "{\"joint\": " + jsonString(entityRef(scene, j.joint, &world)) + ", \"a\": " +
                     jsonString(entityRef(scene, j.a, &world)) +
                     ", \"b\": " + (j.b.isNull() ? std::string("null") : jsonString(entityRef(scene, j.b, &world))) +
                     ", \"anchor_a\": " + vector(j.anchorA) + ", \"anchor_b\": " + vector(j.anchorB) +
                     ", \"separation\": " + number(j.separation) + ", \"force\": " + vector(j.force) +
                     ", \"torque\": " + number(j.torque + 0.0) + ", \"angle\": " + number(j.angle + 0.0) + "}";
        }
        jsonl += "]";
    }
    jsonl += "}\n";
    // A line of its own for each body entering or leaving a sensor, after
    // the step's line: {"event": "begin" or "end", "step", "time",
    // "sensor", "body"} (the same shape as a joint's "break" line).
    // And for each copy an emitter added or removed at the step's start:
    // {"event": "emit" or "remove", "step", "time", "emitter", "copy"}.
    for (const EmitterEvent& e : world.emitterEvents())
        jsonl += std::string("{\"event\": \"") + (e.added ? "emit" : "remove") + "\", \"step\": " +
                 std::to_string(step) + ", \"time\": " + number(world.time()) +
                 ", \"emitter\": " + jsonString(entityRef(scene, e.emitter, &world)) + ", \"copy\": " + jsonString(e.copy) +
                 "}\n";
    for (const SensorEvent& e : world.sensorEvents())
        jsonl += std::string("{\"event\": \"") + (e.begin ? "begin" : "end") + "\", \"step\": " + std::to_string(step) +
                 ", \"time\": " + number(world.time()) + ", \"sensor\": " + jsonString(entityRef(scene, e.sensor, &world)) +
                 ", \"body\": " + jsonString(entityRef(scene, e.body, &world)) + "}\n";
}

/// One JSON line per joint that broke in this step, after the step's line:
/// which joint, its ends, the step and the force that broke it.
void appendBreakLines(std::string& jsonl, std::uint64_t step, const World& world, const Scene& scene) {
    for (const JointBreak& b : world.jointBreaks()) {
        if (b.step != step) continue;
        jsonl += "{\"event\": \"break\", \"step\": " + std::to_string(step) + ", \"time\": " + number(world.time()) +
                 ", \"joint\": " + jsonString(entityRef(scene, b.joint, &world)) +
                 ", \"a\": " + jsonString(entityRef(scene, b.a, &world)) +
                 ", \"b\": " + (b.b.isNull() ? std::string("null") : jsonString(entityRef(scene, b.b, &world))) +
                 ", \"force\": " + number(b.force) + ", \"max_force\": " + number(b.maxForce) + "}\n";
    }
}

/// "step 12: joint \"left rope\" broke: force 1250.3 N past its max_force 1000 N".
std::string breakNote(const JointBreak& b, const Scene& scene) {
    char forces[96];
    std::snprintf(forces, sizeof forces, "force %.6g N past its max_force %.6g N", b.force, b.maxForce);
    return "step " + std::to_string(b.step) + ": joint " + jsonString(entityRef(scene, b.joint)) + " broke: " + forces;
}

/// Ctrl-C (SIGINT) or SIGTERM during the steps: the loop stops, the
/// temporaries are removed and nothing is written.

/// "45 s", "12 min", "3.2 h", "4.1 days", "2.3e+04 years".
std::string duration(double seconds) {
    char buffer[48];
    if (seconds < 120) std::snprintf(buffer, sizeof buffer, "%.0f s", seconds);
    else if (seconds < 7200) std::snprintf(buffer, sizeof buffer, "%.0f min", seconds / 60);
    else if (seconds < 2 * 86400) std::snprintf(buffer, sizeof buffer, "%.1f h", seconds / 3600);
    else if (seconds < 365.25 * 86400) std::snprintf(buffer, sizeof buffer, "%.1f days", seconds / 86400);
    else std::snprintf(buffer, sizeof buffer, "%.2g years", seconds / (365.25 * 86400));
    return buffer;
}

/// Nothing when every energy is finite, else what became non-finite (a
/// divergence): an energy of -inf or NaN in a report is a non-finite value
/// like any other. The totals, then the first entity whose term is not
/// finite and which term.
std::optional<Error> nonFiniteEnergy(const World& world, const EnergyReport& e, long long step) {
    if (std::isfinite(e.total()) && std::isfinite(e.momentum.x) && std::isfinite(e.momentum.y)) return std::nullopt;
    const std::string term = world.nonFiniteEnergyTerm();
    return Error{"step " + std::to_string(step) + ": the total energy became " + number(e.total()) + " J (kinetic " +
                     number(e.kinetic) + ", gravity " + number(e.gravity) + ", springs " + number(e.springs) +
                     ", attractors " + number(e.attractors) + " J; momentum " + number(e.momentum.x) + ", " +
                     number(e.momentum.y) + " kg m/s)" + (term.empty() ? "" : "; first " + term),
                 "", ErrorKind::Diverged};
}

/// Smallest bytes a trace row and a contacts line can take, for the check
/// that the disk can hold the run's files at all.
constexpr double kMinTraceRowBytes = 26;     // "1,0.01,0,0,0,0,0,0,0,0,0\n"
constexpr double kMinContactLineBytes = 39;  // {"step": 1, "time": 0, "contacts": []}

/// Refuses a run whose trace or contacts file cannot fit on its disk even
/// at the smallest row size: 1e18 steps would otherwise run until killed.
std::string checkOutputSpace(const std::optional<std::string>& path, const char* option, long long steps,
                             double bytesPerStep) {
    if (!path) return {};
    const std::filesystem::path p(*path);
    const std::filesystem::path folder = p.has_parent_path() ? p.parent_path() : std::filesystem::path(".");
    struct statvfs fs {};
    if (::statvfs(folder.c_str(), &fs) != 0) return {};
    const double free = double(fs.f_bavail) * double(fs.f_frsize);
    const double need = (double(steps) + 1.0) * bytesPerStep;
    if (need <= free) return {};
    char figures[96];
    std::snprintf(figures, sizeof figures, "%.3g bytes (%.0f a step)", need, bytesPerStep);
    char available[32];
    std::snprintf(available, sizeof available, "%.3g", free);
    return std::string(option) + ": " + std::to_string(steps) + " steps need at least " + figures +
           "; the disk holding " + *path + " has " + available + " free";
}

int run(const RunOptions& options) {
    std::optional<Scene> scene = loadLevelOrReport(options.level);
    if (!scene) return kExitBadInput;
    // Every output is checked before any step, so a bad one costs nothing
    // and nothing is written.
    std::vector<OutputFile> outputs;
    if (options.out) outputs.push_back({"--out", *options.out});
    if (options.trace) outputs.push_back({"--trace", *options.trace});
    if (options.contacts) outputs.push_back({"--contacts", *options.contacts});
    if (Result<void> checked = checkOutputs({options.level}, outputs); !checked) {
        reportOutputProblem(checked.failure());
        return kExitBadInput;
    }
    for (std::string problem : {checkOutputSpace(options.trace, "--trace", options.steps, kMinTraceRowBytes),
                                checkOutputSpace(options.contacts, "--contacts", options.steps, kMinContactLineBytes)})
        if (!problem.empty()) {
            reportError(problem);
            return kExitBadInput;
        }
    if (options.dt) scene->world.dt = *options.dt;
    if (options.integrator) scene->world.integrator = *options.integrator;

    Result<World> built = World::build(*scene);
    if (!built) {
        reportError(options.level + ": cannot simulate: " + built.error());
        return kExitBadInput;
    }
    World& world = built.value();
    // Before playing: a pile, an impact or joint loops the level's substeps cannot hold (stderr, so
    // the summary on stdout stays one line).
    if (const std::optional<PileHint> pile = world.pileHint())
        std::cerr << options.level << ": warning: " << pile->message() << "\n";
    if (const std::optional<ContactStiffnessHint> stiffness = world.contactStiffnessHint())
        std::cerr << options.level << ": warning: " << stiffness->message() << "\n";
    if (const std::optional<ImpactHint> impact = world.impactHint())
        std::cerr << options.level << ": warning: " << impact->message() << "\n";
    if (const std::optional<JointLoopHint> loops = world.jointLoopHint())
        std::cerr << options.level << ": warning: " << loops->message() << "\n";
    if (const std::optional<JointSupportHint> load = world.jointSupportHint())
        std::cerr << options.level << ": warning: " << load->message() << "\n";
    if (const std::optional<DroppedImpulses> dropped = world.droppedImpulses())
        std::cerr << options.level << ": warning: " << dropped->message() << "\n";

    // The trace and contacts stream into temporaries next to their targets
    // (memory stays flat however long the run); they are put in place only
    // when the whole run succeeded.
    std::optional<StreamedFileWriter> trace, contacts;
    for (auto [path, writer] : {std::pair{&options.trace, &trace}, std::pair{&options.contacts, &contacts}}) {
        if (!*path) continue;
        Result<StreamedFileWriter> opened = StreamedFileWriter::open(**path);
        if (!opened) {
            std::cerr << opened.error() << "\n";
            return kExitBadInput;
        }
        writer->emplace(std::move(*opened));
    }
    std::string row;
    std::optional<std::string> failure;  // a write error: exit 2
    auto emit = [&](std::optional<StreamedFileWriter>& writer) {
        if (Result<void> written = writer->write(row); !written && !failure) failure = written.error();
        row.clear();
    };
    std::optional<Error> divergence;
    if (trace) {
        row = "step,time,kinetic,potential_gravity,potential_springs,potential_attractors,potential,total,"
              "momentum_x,momentum_y,contacts\n";
        appendTraceRow(row, 0, world);
        emit(trace);
        divergence = nonFiniteEnergy(world, world.energy(), 0);
    }

    std::optional<CooperativeInterrupts> stepLoop(std::in_place);
    const bool terminal = ::isatty(2) != 0;
    bool progressShown = false, estimateShown = false;
    const auto start = std::chrono::steady_clock::now();
    auto lastProgress = start;
    // One step loop for every front end (advance()); the hooks stop it on an
    // interrupt or a write failure, stream the rows and show the progress.
    std::uint64_t stepsWanted = divergence ? 0 : std::uint64_t(options.steps);
    const AdvanceResult advanced = advance(
        world, stepsWanted,
        {.beforeStep = [&](std::uint64_t) { return !interruptRequested() && !failure; },
         .afterStep = [&](std::uint64_t step) {
             if (trace) {
                 const EnergyReport e = world.energy();
                 if (std::optional<Error> bad = nonFiniteEnergy(world, e, (long long)step)) {
                     divergence = std::move(bad);
                     return false;
                 }
                 appendTraceRow(row, step, world);
                 emit(trace);
             }
             if (contacts) {
                 appendContactLine(row, step, world, *scene);
                 appendBreakLines(row, step, world, *scene);
                 emit(contacts);
             }
             // A break is news whether or not a trace is written.
             if (!world.jointBreaks().empty() && world.jointBreaks().back().step == step) {
                 if (progressShown) std::fputc('\n', stderr);
                 progressShown = false;
                 for (const JointBreak& b : world.jointBreaks())
                     if (b.step == step) std::cerr << options.level << ": note: " << breakNote(b, *scene) << "\n";
             }
             // A clock read every 256 steps: a progress line on a terminal twice
             // a second, and once, after a second, the estimate of the whole run
             // when it is long (on any stderr: a log shows it too).
             if ((step & 255) != 0) return true;
             const auto now = std::chrono::steady_clock::now();
             const double elapsed = std::chrono::duration<double>(now - start).count();
             const double perStep = elapsed / double(step);
             const double left = perStep * double(std::uint64_t(options.steps) - step);
             if (!estimateShown && elapsed >= 1.0) {
                 estimateShown = true;
                 if (elapsed + left > 30.0) {
                     if (progressShown) std::fputc('\n', stderr);
                     std::fprintf(stderr,
                                  "stepwise: note: %s: %lld steps at %.3g ms/step take about %s; Ctrl-C stops the run "
                                  "and writes nothing\n",
                                  options.level.c_str(), options.steps, 1e3 * perStep,
                                  duration(elapsed + left).c_str());
                     progressShown = false;
                 }
             }
             if (terminal && std::chrono::duration<double>(now - lastProgress).count() >= 0.5) {
                 lastProgress = now;
                 std::fprintf(stderr, "\rstep %llu of %lld (%.1f%%), %.3g steps/s, about %s left   ",
                              (unsigned long long)step, options.steps, 100.0 * double(step) / double(options.steps),
                              1.0 / perStep, duration(left).c_str());
                 std::fflush(stderr);
                 progressShown = true;
             }
             return true;
         }});
    const long long taken = (long long)advanced.taken;
    if (advanced.divergence) divergence = advanced.divergence;
    const bool interrupted = interruptRequested();
    stepLoop.reset();  // from here an interrupt exits at once
    if (progressShown) std::fputc('\n', stderr);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    std::string notWritten;
    for (const OutputFile& o : outputs) notWritten += (notWritten.empty() ? "" : ", ") + o.option;
    notWritten = notWritten.empty() ? "no output written" : notWritten + " not written";
    if (failure) {
        std::cerr << *failure << "\n";
        return kExitBadInput;
    }
    if (interrupted) {
        reportError(options.level + ": interrupted at step " + std::to_string(taken) + " of " +
                    std::to_string(options.steps) + "; " + notWritten);
        return 128 + SIGINT;
    }
    const EnergyReport energy = world.energy();
    if (!divergence) {
        divergence = nonFiniteEnergy(world, energy, taken);
    }
    if (divergence) {
        reportError(options.level + ": simulation diverged at " + divergence->message + " (integrator " +
                    world.settings().integrator + ", dt " + number(world.settings().dt) + "); " + notWritten);
        return kExitDiverged;
    }
    // Put in place only now: the streams are complete on disk first, then
    // the scene is saved, then the streams are renamed over their targets.
    for (std::optional<StreamedFileWriter>* writer : {&trace, &contacts})
        if (*writer)
            if (Result<void> done = (*writer)->finish(); !done) {
                std::cerr << done.error() << "\n";
                return kExitBadInput;
            }
    if (options.out) {
        // The solver's warm start goes with the state, so that running the
        // written file on gives the same bits as running on here.
        world.writeBack(*scene);
        SolverState solver = world.solverState();
        scene->solverState = solver.empty() ? std::nullopt : std::optional<SolverState>(std::move(solver));
        if (Result<void> saved = saveSceneFile(*scene, *options.out); !saved) {
            std::cerr << saved.error() << "\n";
            return kExitBadInput;
        }
    }
    for (std::optional<StreamedFileWriter>* writer : {&trace, &contacts})
        if (*writer)
            if (Result<void> done = (*writer)->commit(); !done) {
                std::cerr << done.error() << "\n";
                return kExitBadInput;
            }
    std::cout << options.level << ": ran " << taken << " steps of " << number(world.settings().dt) << " s ("
              << world.settings().substeps << " substep" << (world.settings().substeps == 1 ? "" : "s") << ") with "
               << world.settings().integrator << "; t = " << number(world.time()) << " s; "
              << world.bodyCount() - world.kinematicCount() << " dynamic bodies"
              << (world.kinematicCount() ? " and " + std::to_string(world.kinematicCount()) + " kinematic" : std::string())
              << (world.emitterCount() ? "; " + std::to_string(world.copiesAlive()) + " emitted cop" +
                                             (world.copiesAlive() == 1 ? "y" : "ies") + " alive"
                                       : std::string())
              << "; total energy " << number(energy.total()) << " J; "
              << number(taken ? 1e3 * seconds / double(taken) : 0.0) << " ms/step";
    if (const std::size_t broke = world.jointBreaks().size())
        std::cout << "; " << broke << " joint" << (broke == 1 ? "" : "s") << " broke";
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
    cmd->add_option("--dt", options->dt, "Seconds per step, in (0, 10] (overrides world.dt)")->check(secondsPerStep());
    cmd->add_option("--integrator", options->integrator, "Integrator (overrides world.integrator)")
        ->check(CLI::IsMember(std::vector<std::string>(integratorNames().begin(), integratorNames().end())));
    cmd->add_option("--out", options->out, "Write the resulting scene here (atomic)")->check(outputFileName());
    cmd->add_option("--trace", options->trace,
                    "Write a CSV row per step (step 0 is the initial state): time, energies, momentum, contacts")
        ->check(outputFileName());
    cmd->add_option("--contacts", options->contacts,
                    "Write one JSON line per step: the step, the time and every contact (entities, point, normal, "
                    "depth, normal and tangent impulse); with joints, every joint too (anchors, separation, "
                    "reaction force and torque on b, angle). After a step's line, a line of its own for each event "
                    "of that step: a body entering or leaving a sensor ({\"event\": \"begin\" or \"end\", ..., "
                    "\"sensor\", \"body\"}) and a joint breaking ({\"event\": \"break\", ...} with the force)")
        ->check(outputFileName());
    cmd->callback([options, &exitCode] { exitCode = run(*options); });
}

} // namespace stepwise::cli
