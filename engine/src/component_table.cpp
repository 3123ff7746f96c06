// The component table: the single source of truth for component names,
// fields, defaults and validation rules. See component_table.hpp.

#include "stepwise/component_table.hpp"

#include "stepwise/components.hpp"

#include "field_builder.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>

namespace stepwise {

namespace {

constexpr NumberRange kAny = kAnyMagnitude;
constexpr NumberRange kPositive{0.0, kMaxMagnitude, true};
constexpr NumberRange kNonNegative{0.0, kMaxMagnitude, false};
/// Masses and shape sizes: their squares and products (inertia m r^2, and
/// its inverse) stay normal doubles.
constexpr NumberRange kSize{kMinSize, kMaxMagnitude, false};
constexpr NumberRange kUnit{0.0, 1.0, false};
constexpr NumberRange kGroup{-2147483647.0, 2147483647.0, false};

template <auto Member>
FieldInfo field(std::string_view key, NumberRange range, std::string_view unit, std::string_view description) {
    return detail::makeField<Member>(key, range, unit, description);
}

/// Fills the type-erased registry operations for component struct T.
template <class T>
ComponentInfo row(std::string_view name, std::string_view description, bool inlineValue,
                  std::vector<std::string_view> requires_, std::vector<FieldInfo> fields,
                  std::optional<Error> (*finish)(void*) = nullptr) {
    ComponentInfo info;
    info.name = name;
    info.description = description;
    info.inlineValue = inlineValue;
    info.requires_ = std::move(requires_);
    info.fields = std::move(fields);
    info.has = [](const Registry& r, Entity e) { return r.has<T>(e); };
    info.get = [](Registry& r, Entity e) -> void* { return r.tryGet<T>(e); };
    info.getConst = [](const Registry& r, Entity e) -> const void* { return r.tryGet<T>(e); };
    info.emplaceDefault = [](Registry& r, Entity e) -> void* { return &r.emplace<T>(e, T{}); };
    info.remove = [](Registry& r, Entity e) { return r.remove<T>(e); };
    info.finish = finish;
    return info;
}

/// A number as the loader's messages show it ("%g"-like, short).
std::string describeNumber(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

std::optional<Error> finishPlane(void* component) {
    auto& plane = *static_cast<Plane*>(component);
    // hypot, not sqrt(x*x + y*y): a normal of 1e200 would overflow to inf
    // and normalise to (0, 0).
    const double len = std::hypot(plane.normal.x, plane.normal.y);
    if (!(len > 1e-12)) return Error{"expected a non-zero vector, got {\"x\": 0, \"y\": 0}", "normal"};
    // A normal that is already unit length up to rounding is kept bit for
    // bit. Dividing it by its own rounded length would move its last bits on
    // every load, so load -> save -> load -> save would not give the same
    // bytes ({1, 2} would not). 8 ulp covers the rounding of n / |n|.
    if (std::abs(len - 1.0) <= 8.0 * std::numeric_limits<double>::epsilon()) return {};
    // The offset is measured along the normal as written (n.p >= d); keep the
    // same half-plane after normalising n by scaling d with it.
    const double offset = plane.offset / len;
    if (!(std::abs(offset) <= kMaxMagnitude))
        return Error{"expected an offset that stays within " + formatNumber(kMaxMagnitude) +
                         " once the normal is normalised (offset / |normal|), got " +
                         describeNumber(plane.offset) + " with |normal| = " + describeNumber(len),
                     "offset"};
    plane.normal = plane.normal / len;
    plane.offset = offset;
    return {};
}

std::optional<Error> finishPolygon(void* component) {
    std::optional<Error> problem = polygonProblem(static_cast<Polygon*>(component)->vertices);
    if (!problem) return {};
    return problem->within("vertices");
}

std::optional<Error> finishCapsule(void* component) {
    const auto& capsule = *static_cast<Capsule*>(component);
    if (capsule.a == capsule.b)
        return Error{"a and b are the same point {\"x\": " + formatNumber(capsule.a.x) + ", \"y\": " +
                         formatNumber(capsule.a.y) + "}; a capsule needs a segment of non-zero length (a circle is "
                         "the shape without one)",
                     "b"};
    return {};
}

std::optional<Error> finishShapes(void* component) {
    const auto& shapes = *static_cast<Shapes*>(component);
    if (shapes.items.empty()) return Error{"expected at least one shape, got none"};
    // A saved contact names its shape by a one-byte index (shape_a, shape_b).
    if (shapes.items.size() > 256)
        return Error{"expected at most 256 shapes, got " + std::to_string(shapes.items.size())};
    for (std::size_t i = 0; i < shapes.items.size(); ++i)
        if (std::optional<Error> problem = compoundShapeProblem(shapes.items[i]))
            return problem->within(std::to_string(i));
    return {};
}

std::optional<Error> finishChain(void* component) {
    const auto& chain = *static_cast<Chain*>(component);
    std::optional<Error> problem = chainProblem(chain.points, chain.loop);
    if (!problem) return {};
    return problem->within("points");
}

std::optional<Error> finishSpring(void* component) {
    auto& spring = *static_cast<Spring*>(component);
    if (spring.a.isNull()) return Error{"expected the name of an entity, got nothing", "a"};
    if (spring.b.isNull() == !spring.anchor.has_value()) {
        return Error{spring.b.isNull() ? "expected either \"b\" (an entity name) or \"anchor\" (a point), got neither"
                                       : "expected either \"b\" or \"anchor\", got both"};
    }
    // a == b is checked with the names at hand: checkSceneRelations.
    return {};
}

constexpr std::string_view kJointTypes[] = {"hinge", "slider", "weld", "distance", "rope", "wheel"};

std::optional<Error> finishJoint(void* component) {
    auto& joint = *static_cast<Joint*>(component);
    if (joint.type.empty())
        return Error{"expected one of hinge, slider, weld, distance, rope, wheel, got nothing", "type"};
    if (std::find(std::begin(kJointTypes), std::end(kJointTypes), joint.type) == std::end(kJointTypes)) {
        std::string message = "expected one of hinge, slider, weld, distance, rope, wheel, got \"" + joint.type + "\"";
        if (auto guess = closestName(joint.type, kJointTypes)) message += "; did you mean \"" + std::string(*guess) + "\"?";
        return Error{message, "type"};
    }
    if (joint.a.isNull()) return Error{"expected the name of a body, got nothing", "a"};
    if (joint.lower && joint.upper && *joint.lower > *joint.upper)
        return Error{"expected at most upper (" + describeNumber(*joint.upper) + "), got " + describeNumber(*joint.lower),
                     "lower"};
    return {};
}

std::optional<Error> finishBoid(void* component) {
    auto& boid = *static_cast<Boid*>(component);
    if (boid.separationRadius > boid.neighborRadius)
        return Error{"expected at most neighbor_radius (" + std::to_string(boid.neighborRadius) + "), got " +
                         std::to_string(boid.separationRadius),
                     "separation_radius"};
    return {};
}

std::vector<ComponentInfo> buildTable() {
    const std::vector<std::string_view> needsPosition{"position"};
    std::vector<ComponentInfo> t;
    t.push_back(row<Name>("name", "unique label; springs refer to entities by it", true, {},
                          {field<&Name::value>("", kAny, "", "unique label")}));
    t.push_back(row<Type>("type", "free label, e.g. \"Water Animal\"", true, {},
                          {field<&Type::value>("", kAny, "", "free label")}));
    t.push_back(row<Position>("position", "centre of the body", true, {},
                              {field<&Position::value>("", kAny, "m", "centre of the body")}));
    t.push_back(row<Velocity>("velocity", "linear velocity", true, needsPosition,
                              {field<&Velocity::value>("", kAnySpeed, "m/s", "linear velocity")}));
    t.push_back(row<Mass>("mass", "mass of a dynamic body", true, needsPosition,
                          {field<&Mass::value>("", kSize, "kg", "mass of a dynamic body")}));
    t.push_back(row<Static>("static", "immovable: infinite mass, never integrated", true, needsPosition,
                            {field<&Static::value>("", kAny, "", "immovable when true")}));
    t.push_back(row<Kinematic>("kinematic", "moved only by its velocity and angular velocity; pushes, is never pushed",
                               true, needsPosition,
                               {field<&Kinematic::value>("", kAny, "", "moves at its own velocity when true")}));
    t.push_back(row<Radius>("radius", "circle shape; the body collides", true, needsPosition,
                            {field<&Radius::value>("", kSize, "m", "circle radius")}));
    t.push_back(row<Box>("box", "box shape, rotated by angle; the body collides", false, needsPosition,
                         {field<&Box::width>("width", kSize, "m", "full width"),
                          field<&Box::height>("height", kSize, "m", "full height")}));
    {
        ComponentInfo polygon = row<Polygon>(
            "polygon", "convex polygon shape, rotated by angle about position; the body collides", false,
            needsPosition,
            {field<&Polygon::vertices>("vertices", NumberRange{3.0, 8.0}, "m",
                                       "3 to 8 vertices relative to position, counter-clockwise, convex"),
             field<&Polygon::radius>("radius", kNonNegative, "m",
                                     "rounds the corners by this radius; the mass includes the rounding")},
            &finishPolygon);
        polygon.finishNamesEntity = true;
        t.push_back(std::move(polygon));
    }
    {
        ComponentInfo capsule = row<Capsule>(
            "capsule", "capsule shape: a segment swept by a radius, rotated by angle about position; the body collides",
            false, needsPosition,
            {field<&Capsule::a>("a", kAny, "m", "one end of the segment, relative to position"),
             field<&Capsule::b>("b", kAny, "m", "the other end of the segment, relative to position"),
             field<&Capsule::radius>("radius", kSize, "m", "radius swept around the segment")},
            &finishCapsule);
        capsule.finishNamesEntity = true;
        t.push_back(std::move(capsule));
    }
    {
        ComponentInfo chain = row<Chain>(
            "chain",
            "chain shape on a static or kinematic body: a smooth one-sided polyline, solid on the right of each segment's "
            "direction; rotated by angle about position",
            false, needsPosition,
            {field<&Chain::points>("points", NumberRange{2.0, double(kMaxChainPoints)}, "m",
                                   "2 to 1024 points relative to position (3 or more with loop); bodies collide on "
                                   "the right of each segment"),
             field<&Chain::loop>("loop", kAny, "", "closes the chain from the last point back to the first")},
            &finishChain);
        chain.finishNamesEntity = true;
        t.push_back(std::move(chain));
        ComponentInfo shapes = row<Shapes>(
            "shapes",
            "compound body: several shapes (circle, box, polygon, capsule) on one body, each with its own material, "
            "filter, sensor and density; the body collides",
            true, needsPosition,
            {field<&Shapes::items>("", NumberRange{1.0, 256.0}, "m",
                                   "the body's shapes in its frame; mass and inertia are their sum")},
            &finishShapes);
        shapes.finishNamesEntity = true;
        t.push_back(std::move(shapes));
    }
    t.push_back(row<Angle>("angle", "orientation, counter-clockwise", true, needsPosition,
                           {field<&Angle::value>("", kAny, "rad", "orientation")}));
    t.push_back(row<AngularVelocity>("angular_velocity", "spin, counter-clockwise", true, needsPosition,
                                     {field<&AngularVelocity::value>("", kAnySpeed, "rad/s", "spin")}));
    t.push_back(row<Color>("color", "display colour", true, {},
                           {field<&Color::value>("", kUnit, "", "display colour, channels in 0..1")}));
    // Material properties: planes have them too, so they need no position.
    t.push_back(row<Restitution>("restitution", "bounciness; a pair uses the larger value", true, {},
                                 {field<&Restitution::value>("", kUnit, "", "coefficient of restitution")}));
    t.push_back(row<Friction>("friction", "Coulomb coefficient; a pair uses sqrt(f1*f2)", true, {},
                              {field<&Friction::value>("", kNonNegative, "", "Coulomb friction coefficient")}));
    t.push_back(row<Drag>("drag", "viscous damping b: force -b*v", true, needsPosition,
                          {field<&Drag::value>("", kNonNegative, "kg/s", "viscous damping coefficient")}));
    t.push_back(row<Sensor>("sensor", "the shape detects bodies entering and leaving but never pushes", true, {},
                            {field<&Sensor::value>("", kAny, "", "detects overlaps only when true")}));
    t.push_back(row<Filter>(
        "filter", "which pairs collide: categories, masks and groups (Box2D's rule)", false, {},
        {field<&Filter::category>("category", kAny, "", "the bits this shape is"),
         field<&Filter::mask>("mask", kAny, "", "the categories it collides with"),
         field<&Filter::group>("group", kGroup, "",
                               "same non-zero group: always collide if positive, never if negative")}));
    t.push_back(row<Plane>("plane", "infinite wall: bodies stay where normal.p >= offset", false, {},
                           {field<&Plane::normal>("normal", kAny, "", "outward normal; normalised on load"),
                            field<&Plane::offset>("offset", kAny, "m", "distance of the wall along the normal")},
                           &finishPlane));
    t.push_back(row<Attractor>("attractor", "Newtonian gravity towards this body (uses world G)", false,
                               needsPosition,
                               {field<&Attractor::softening>("softening", kNonNegative, "m",
                                                             "softening length eps")}));
    t.push_back(row<Spring>(
        "spring", "spring-damper between entities a and b, or a and a fixed anchor", false, {},
        {field<&Spring::a>("a", kAny, "", "name of the first entity"),
         field<&Spring::b>("b", kAny, "", "name of the second entity (or use anchor)"),
         field<&Spring::anchor>("anchor", kAny, "m", "fixed world point instead of b"),
         field<&Spring::k>("k", kNonNegative, "N/m", "stiffness"),
         field<&Spring::damping>("damping", kNonNegative, "N*s/m", "damping along the axis"),
         field<&Spring::restLength>("rest_length", kNonNegative, "m",
                                    "natural length; absent: the distance at load")},
        &finishSpring));
    t.push_back(row<Boid>(
        "boid", "flocking proxy forces: separation, alignment, cohesion, goal", false, needsPosition,
        {field<&Boid::neighborRadius>("neighbor_radius", kPositive, "m", "neighbours are closer than this"),
         field<&Boid::separationRadius>("separation_radius", kNonNegative, "m", "push apart when closer"),
         field<&Boid::separation>("separation", kNonNegative, "m/s^2", "weight of separation"),
         field<&Boid::alignment>("alignment", kNonNegative, "m/s^2", "weight of alignment"),
         field<&Boid::cohesion>("cohesion", kNonNegative, "m/s^2", "weight of cohesion"),
         field<&Boid::goal>("goal", kAny, "m", "point to seek"),
         field<&Boid::goalWeight>("goal_weight", kNonNegative, "m/s^2", "weight of seeking the goal"),
         field<&Boid::maxSpeed>("max_speed", NumberRange{0.0, kMaxSpeed, true}, "m/s", "speed limit of steering")},
        &finishBoid));
    t.push_back(row<Template>("template", "a prefab for emitters: not simulated, copied whole with every entity "
                                          "of the same template value",
                              true, {}, {field<&Template::value>("", kAny, "", "the template's name")}));
    t.push_back(row<Emitter>(
        "emitter", "adds a copy of a template at its position every interval seconds", false, needsPosition,
        {field<&Emitter::templateName>("template", kAny, "", "the template value of the entities it copies"),
         field<&Emitter::interval>("interval", kPositive, "s", "seconds between copies"),
         field<&Emitter::count>("count", NumberRange{1.0, 100000.0}, "", "copies alive at most; the oldest goes first"),
         field<&Emitter::velocity>("velocity", kAnySpeed, "m/s", "velocity of each copy before the random turn"),
         field<&Emitter::spread>("spread", NumberRange{0.0, 3.141592653589793}, "rad",
                                 "each copy's velocity turns by a random angle in +/- spread (world.seed)"),
         field<&Emitter::lifetime>("lifetime", kPositive, "s", "seconds a copy lives; absent: until count pushes it out"),
         field<&Emitter::next>("next", kAny, "s", "run state: world time of the next copy; absent: the time at load"),
         field<&Emitter::emitted>("emitted", NumberRange{0.0, 2147483647.0}, "", "run state: copies made so far"),
         field<&Emitter::alive>("alive", NumberRange{0.0, 100000.0}, "", "run state: the newest this many are alive"),
         field<&Emitter::oldest>("oldest", kAny, "s", "run state: when the oldest copy alive appeared"),
         field<&Emitter::copies>("copies", NumberRange{1.0, 2147483647.0}, "",
                                 "run state: the numbers of its copies alive, oldest first; absent: the alive "
                                 "numbers up to emitted")}));
    {
        FieldInfo type = field<&Joint::type>("type", kAny, "", "hinge, slider, weld, distance, rope or wheel");
        type.choices = kJointTypes;
        t.push_back(row<Joint>(
            "joint", "constraint between bodies a and b (b absent: the world); on its own entity", false, {},
            {type,
             field<&Joint::a>("a", kAny, "", "name of the first body"),
             field<&Joint::b>("b", kAny, "", "name of the second body; absent: the world"),
             field<&Joint::localA>("local_a", kAny, "m", "anchor in a's frame"),
             field<&Joint::localB>("local_b", kAny, "m", "anchor in b's frame (a world point for the world)"),
             field<&Joint::anchor>("anchor", kAny, "m", "one world point that sets local_a and local_b on load"),
             field<&Joint::axis>("axis", kAny, "", "slider, wheel: direction of travel in a's frame; absent {1, 0}"),
             field<&Joint::referenceAngle>("reference_angle", kAny, "rad",
                                           "angle of b relative to a that counts as zero; absent: as loaded"),
             field<&Joint::lower>("lower", kAny, "rad or m", "hinge: lowest angle; slider, wheel: lowest travel"),
             field<&Joint::upper>("upper", kAny, "rad or m", "hinge: highest angle; slider, wheel: highest travel"),
             field<&Joint::motorSpeed>("motor_speed", kAnySpeed, "rad/s or m/s", "motor target speed; absent 0"),
             field<&Joint::maxMotorTorque>("max_motor_torque", kNonNegative, "N*m", "hinge, wheel motor: largest torque"),
             field<&Joint::maxMotorForce>("max_motor_force", kNonNegative, "N", "slider motor: largest force"),
             field<&Joint::length>("length", kNonNegative, "m", "distance, rope: length; absent: as loaded"),
             field<&Joint::stiffnessHz>("stiffness_hz", kNonNegative, "Hz",
                                        "weld, distance: softness, 0 rigid; wheel: axis spring, 0 none"),
             field<&Joint::dampingRatio>("damping_ratio", kNonNegative, "", "weld, distance, wheel: damping; absent 1"),
             field<&Joint::springHz>("spring_hz", kNonNegative, "Hz",
                                     "hinge: rotational spring toward reference_angle; absent or 0 none"),
             field<&Joint::springDampingRatio>("spring_damping_ratio", kNonNegative, "",
                                               "hinge spring's damping ratio; absent 1"),
             field<&Joint::maxForce>("max_force", kPositive, "N", "breaks past this force; absent never"),
             field<&Joint::collideConnected>("collide_connected", kAny, "", "a and b still collide")},
            &finishJoint));
    }
    return t;
}

std::size_t editDistance(std::string_view a, std::string_view b) {
    std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        cur[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
            cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
        }
        std::swap(prev, cur);
    }
    return prev[b.size()];
}

} // namespace

std::span<const std::string_view> jointTypeNames() { return kJointTypes; }

std::string NumberRange::describe(bool integer) const {
    std::ostringstream out;
    auto num = [integer](double v) {
        // An integer bound in full: 2147483647, not 2.14748e+09.
        if (integer) return std::to_string(static_cast<long long>(v));
        std::ostringstream s;
        s << v;
        return s.str();
    };
    const char* what = integer ? "an integer" : "a number";
    const bool hasMin = std::isfinite(min), hasMax = std::isfinite(max);
    if (hasMin && hasMax && !minExclusive) out << what << " in [" << num(min) << ", " << num(max) << "]";
    else if (hasMin && hasMax) out << what << " in (" << num(min) << ", " << num(max) << "]";
    else if (hasMin) out << what << (minExclusive ? " > " : " >= ") << num(min);
    else if (hasMax) out << what << " <= " << num(max);
    else out << (integer ? "an integer" : "a finite number");
    return out.str();
}

std::string formatNumber(double value) {
    char buffer[32];
    const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
    return error == std::errc() ? std::string(buffer, end) : std::string("?");
}

std::optional<Error> fieldValueProblem(const FieldInfo& field, const void* member) {
    auto number = [&](double v, bool integer) -> std::optional<Error> {
        if (!std::isfinite(v)) return Error{"expected a finite number, got " + formatNumber(v)};
        if (!field.range.contains(v) || (integer && v != std::floor(v)))
            return Error{"expected " + field.range.describe(integer) + ", got " + formatNumber(v)};
        return std::nullopt;
    };
    auto vector = [](Vec2 v, const NumberRange& axis) -> std::optional<Error> {
        if (axis.contains(v.x) && axis.contains(v.y)) return std::nullopt;
        return Error{std::string(isFinite(v) ? "expected each axis in [" + formatNumber(axis.min) + ", " +
                                                   formatNumber(axis.max) + "]"
                                             : "expected finite numbers") +
                     ", got {\"x\": " + formatNumber(v.x) + ", \"y\": " + formatNumber(v.y) + "}"};
    };
    switch (field.kind) {
    case FieldKind::Number: return number(*static_cast<const double*>(member), false);
    case FieldKind::Integer: return number(*static_cast<const int*>(member), true);
    case FieldKind::OptionalNumber: {
        const auto& v = *static_cast<const std::optional<double>*>(member);
        return v ? number(*v, false) : std::nullopt;
    }
    case FieldKind::Vector: return vector(*static_cast<const Vec2*>(member), field.range);
    case FieldKind::OptionalVector: {
        const auto& v = *static_cast<const std::optional<Vec2>*>(member);
        return v ? vector(*v, field.range) : std::nullopt;
    }
    case FieldKind::VectorList:
        for (const Vec2 p : *static_cast<const std::vector<Vec2>*>(member))
            if (auto problem = vector(p, kAnyMagnitude)) return problem;
        return std::nullopt;
    case FieldKind::IntegerList:
        for (const int n : *static_cast<const std::vector<int>*>(member))
            if (auto problem = number(n, true)) return problem;
        return std::nullopt;
    case FieldKind::ShapeList:
        for (const CompoundShape& s : *static_cast<const std::vector<CompoundShape>*>(member)) {
            for (const Vec2 p : {s.center, s.a, s.b})
                if (auto problem = vector(p, kAnyMagnitude)) return problem;
            for (const Vec2 p : s.vertices)
                if (auto problem = vector(p, kAnyMagnitude)) return problem;
        }
        return std::nullopt;
    case FieldKind::Color: {
        const Rgb c = *static_cast<const Rgb*>(member);
        for (const double channel : {c.r, c.g, c.b})
            if (auto problem = number(channel, false)) return Error{"colour channels: " + problem->message};
        return std::nullopt;
    }
    case FieldKind::String: {
        const auto& value = *static_cast<const std::string*>(member);
        if (field.choices.empty() ||
            std::find(field.choices.begin(), field.choices.end(), value) != field.choices.end())
            return std::nullopt;
        std::string message = "expected one of ";
        for (std::size_t i = 0; i < field.choices.size(); ++i)
            message += (i ? ", " : "") + std::string(field.choices[i]);
        message += ", got \"" + value + "\"";
        if (auto guess = closestName(value, field.choices)) message += "; did you mean \"" + std::string(*guess) + "\"?";
        return Error{message};
    }
    case FieldKind::Bool:
    case FieldKind::Bits:
    case FieldKind::EntityRef: return std::nullopt;
    }
    return std::nullopt;
}

std::span<const ComponentInfo> componentTable() {
    static const std::vector<ComponentInfo> table = buildTable();
    return table;
}

const ComponentInfo* findComponent(std::string_view name) {
    for (const ComponentInfo& info : componentTable())
        if (info.name == name) return &info;
    return nullptr;
}

std::vector<std::string_view> componentNames() {
    std::vector<std::string_view> names;
    for (const ComponentInfo& info : componentTable()) names.push_back(info.name);
    return names;
}

std::optional<std::string_view> closestName(std::string_view name,
                                            std::span<const std::string_view> candidates) {
    std::optional<std::string_view> best;
    std::size_t bestDistance = std::max<std::size_t>(2, name.size() / 3) + 1;
    for (std::string_view c : candidates) {
        // The distance is at least the difference in length: skip before
        // the O(|name| |c|) table (a 10 MB unknown name would take seconds).
        const std::size_t lengthGap = name.size() > c.size() ? name.size() - c.size() : c.size() - name.size();
        if (lengthGap >= bestDistance) continue;
        const std::size_t d = editDistance(name, c);
        if (d < bestDistance) {
            bestDistance = d;
            best = c;
        }
    }
    return best;
}

namespace {

void copyField(const FieldInfo& field, const void* src, void* dst) {
    // FieldInfo::address takes a non-const pointer; reading through it does
    // not modify the source.
    void* from = field.address(const_cast<void*>(src));
    void* to = field.address(dst);
    switch (field.kind) {
    case FieldKind::Number: *static_cast<double*>(to) = *static_cast<const double*>(from); break;
    case FieldKind::Integer: *static_cast<int*>(to) = *static_cast<const int*>(from); break;
    case FieldKind::Bits: *static_cast<std::uint32_t*>(to) = *static_cast<const std::uint32_t*>(from); break;
    case FieldKind::OptionalNumber:
        *static_cast<std::optional<double>*>(to) = *static_cast<const std::optional<double>*>(from);
        break;
    case FieldKind::Vector: *static_cast<Vec2*>(to) = *static_cast<const Vec2*>(from); break;
    case FieldKind::OptionalVector:
        *static_cast<std::optional<Vec2>*>(to) = *static_cast<const std::optional<Vec2>*>(from);
        break;
    case FieldKind::Color: *static_cast<Rgb*>(to) = *static_cast<const Rgb*>(from); break;
    case FieldKind::Bool: *static_cast<bool*>(to) = *static_cast<const bool*>(from); break;
    case FieldKind::VectorList:
        *static_cast<std::vector<Vec2>*>(to) = *static_cast<const std::vector<Vec2>*>(from);
        break;
    case FieldKind::ShapeList:
        *static_cast<std::vector<CompoundShape>*>(to) = *static_cast<const std::vector<CompoundShape>*>(from);
        break;
    case FieldKind::IntegerList: *static_cast<std::vector<int>*>(to) = *static_cast<const std::vector<int>*>(from); break;
    case FieldKind::String: *static_cast<std::string*>(to) = *static_cast<const std::string*>(from); break;
    case FieldKind::EntityRef: *static_cast<Entity*>(to) = *static_cast<const Entity*>(from); break;
    }
}

} // namespace

void copyComponents(const Registry& src, Entity from, Registry& dst, Entity to) {
    for (const ComponentInfo& info : componentTable()) {
        const void* c = info.getConst(src, from);
        if (!c) continue;
        void* d = info.emplaceDefault(dst, to);
        for (const FieldInfo& f : info.fields) copyField(f, c, d);
    }
}

} // namespace stepwise
