#include "report/scenes.hpp"

#include "stepwise/components.hpp"

#include <cmath>
#include <cstdint>
#include <numbers>

namespace stepwise::report {

Scene attractorDisc(std::size_t n, double theta, const std::string& integrator, double dt) {
    Scene s;
    s.world.gravity = {0.0, 0.0};
    s.world.integrator = integrator;
    s.world.dt = dt;
    s.world.theta = theta;
    std::uint64_t state = 0x9E3779B97F4A7C15ull;
    auto uniform = [&state] {  // splitmix64 -> [0, 1)
        std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return double((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
    };
    s.registry.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
        const double r = std::sqrt(uniform()), a = 2.0 * std::numbers::pi * uniform();
        const Entity e = s.registry.create();
        std::string name = "s";
        name += std::to_string(i);
        s.registry.emplace<Name>(e, {name});
        s.registry.emplace<Position>(e, {{r * std::cos(a), r * std::sin(a)}});
        s.registry.emplace<Velocity>(e, {{0.0, 0.0}});
        s.registry.emplace<Mass>(e, {1.0 / double(n)});
        s.registry.emplace<Attractor>(e, {0.01});
    }
    return s;
}

} // namespace stepwise::report
