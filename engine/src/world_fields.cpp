// The world-settings table. See world_fields.hpp.

#include "stepwise/world_fields.hpp"

#include "stepwise/integrators.hpp"

#include "field_builder.hpp"

#include <limits>


namespace stepwise {

namespace {


std::vector<WorldFieldInfo> buildTable() {
    using detail::makeField;
    FieldInfo integrator = makeField<&WorldSettings::integrator>(
        "integrator", {}, "", "time integrator (docs/physics.md compares them)");
    integrator.choices = integratorNames();
    // Ranges: dt up to 10 s and counts up to 1000 are far past any useful
    // level; they only keep a typo (dt 1e9, 1e9 substeps) from freezing a run.
    // Two of those caps hold for input only (maxGuardsInputOnly): a scene made
    // in code may step longer (implicit methods are tested at dt = 100 s), and
    // dopri5 proposes up to five times its step, which a World takes back
    // when it is reloaded.
    return {
        {makeField<&WorldSettings::gravity>("gravity", kAnyMagnitude, "m/s^2", "applied to every dynamic body")},
        {makeField<&WorldSettings::G>("G", kAnyMagnitude, "N*m^2/kg^2", "gravitational constant for attractors")},
        {integrator},
        {.field = makeField<&WorldSettings::dt>("dt", {0.0, 10.0, true}, "s", "seconds per step"),
         .maxGuardsInputOnly = true},
        {makeField<&WorldSettings::substeps>("substeps", {1.0, double(kMaxLevelSubsteps)}, "",
                                             "each step is substeps steps of dt/substeps; absent: chosen from "
                                             "the scene's structure (its pile, load and joints) and recorded "
                                             "in a saved run's solver_state.chosen"),
         true},
        {makeField<&WorldSettings::time>("time", kAnyMagnitude, "s", "simulated seconds so far")},
        {makeField<&WorldSettings::solverIterations>("solver_iterations", {1.0, double(kMaxLevelSubsteps)}, "",
                                                     "contact solver velocity iterations per substep; absent: 8, "
                                                     "or chosen with substeps when that is absent too"),
         true},
        {makeField<&WorldSettings::restitutionThreshold>(
            "restitution_threshold", {0.0, 1e6}, "m/s",
            "slower impacts do not bounce; absent: derived from gravity and the substep (zero gravity: every "
            "approach bounces)")},
        {makeField<&WorldSettings::tolerance>("tolerance", {0.0, 1.0, true}, "",
                                              "local error per internal step of dopri5 (relative to 1 + |value|)")},
        {makeField<&WorldSettings::theta>("theta", {0.0, 1.0}, "",
                                          "Barnes-Hut opening angle for attractors; 0 = exact pairwise sums, larger is faster "
                                          "and less exact (small scenes are summed exactly whatever theta says)")},
        {.field = makeField<&WorldSettings::adaptiveStep>("adaptive_step", {0.0, 10.0}, "s",
                                                          "dopri5's proposed next internal step, saved for exact "
                                                          "resume; absent: none yet"),
         .optional = true,
         .maxGuardsInputOnly = true},
        {makeField<&WorldSettings::sleep>("sleep", {}, "",
                                          "islands of bodies that stay still for sleep_time sleep (cost nothing) "
                                          "until touched or edited")},
        {makeField<&WorldSettings::sleepVelocity>("sleep_velocity", {0.0, 1e6}, "m/s",
                                                  "a body is still while its fastest point moves slower than this")},
        {makeField<&WorldSettings::sleepTime>("sleep_time", {0.0, 1e6}, "s",
                                              "how long an island must stay still before it sleeps")},
        // Joint softness: above 0 (0 Hz would never correct a joint's error);
        // the solver caps it at half the substep rate whatever is given.
        {makeField<&WorldSettings::jointHz>("joint_hz", {0.0, 1e6, true}, "Hz",
                                            "stiffness of rigid joints' position correction, capped at half the "
                                            "substep rate; absent: the engine's choice (docs/joints.md)")},
        {makeField<&WorldSettings::jointDampingRatio>("joint_damping_ratio", {0.0, 1e3}, "",
                                                      "damping ratio of rigid joints' position correction; absent: "
                                                      "the engine's choice (docs/joints.md)")},
        {makeField<&WorldSettings::seed>("seed", {0.0, 1e9}, "",
                                         "seed of every random choice in a run (emitters' spread); absent: 0"),
         true},
    };
}

} // namespace

bool WorldFieldInfo::isUnset(const WorldSettings& settings) const {
    const void* member = field.address(const_cast<WorldSettings*>(&settings));
    switch (field.kind) {
    case FieldKind::OptionalNumber: return !static_cast<const std::optional<double>*>(member)->has_value();
    case FieldKind::Integer: return optional && *static_cast<const int*>(member) == 0;
    case FieldKind::Number: return optional && *static_cast<const double*>(member) == 0.0;
    default: return false;
    }
}

std::span<const WorldFieldInfo> worldFieldTable() {
    static const std::vector<WorldFieldInfo> table = buildTable();
    return table;
}

const WorldFieldInfo* findWorldField(std::string_view key) {
    for (const WorldFieldInfo& info : worldFieldTable())
        if (info.field.key == key) return &info;
    return nullptr;
}

std::vector<std::string_view> worldFieldNames() {
    std::vector<std::string_view> names;
    for (const WorldFieldInfo& info : worldFieldTable()) names.push_back(info.field.key);
    return names;
}

std::optional<Error> adaptiveStepProblem(const WorldSettings& settings) {
    const double smallest = kSmallestAdaptiveStep * settings.dt;
    if (settings.adaptiveStep == 0.0 || settings.adaptiveStep > smallest) return std::nullopt;
    return Error{"expected 0 (none yet) or more than " + formatNumber(kSmallestAdaptiveStep) + " dt (" +
                 formatNumber(smallest) + " s), dopri5's smallest step, got " + formatNumber(settings.adaptiveStep)};
}

std::optional<Error> worldSettingsProblem(const WorldSettings& settings) {
    for (const WorldFieldInfo& info : worldFieldTable()) {
        if (info.isUnset(settings)) continue;
        FieldInfo field = info.field;
        if (info.maxGuardsInputOnly) field.range.max = std::numeric_limits<double>::infinity();
        const void* member = field.address(const_cast<WorldSettings*>(&settings));
        if (std::optional<Error> problem = fieldValueProblem(field, member))
            return problem->within("world." + std::string(field.key));
    }
    if (std::optional<Error> problem = adaptiveStepProblem(settings)) return problem->within("world.adaptive_step");
    return std::nullopt;
}

} // namespace stepwise
