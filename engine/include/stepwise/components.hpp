#pragma once
/// \file components.hpp
/// Every component a scene entity can carry. Plain structs, no behaviour:
/// systems (forces, integrators, collision) are functions over the entities
/// that have what they need. Names, JSON keys, defaults and validation rules
/// live in one place, the component table (component_table.hpp).
///
/// A component that is absent means "not modelled": no `drag` means no drag
/// pass over that body, no `radius`/`box`/`plane` means the body never enters
/// the collision stages.

#include "stepwise/entity.hpp"
#include "stepwise/result.hpp"
#include "stepwise/vec2.hpp"

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <string>
#include <vector>

namespace stepwise {

/// Unique label; springs name their ends by it.
struct Name { std::string value; };
/// Free label (the course notes' "Water Animal").
struct Type { std::string value; };
/// Centre of the body, metres.
struct Position { Vec2 value; };
/// Linear velocity, m/s.
struct Velocity { Vec2 value; };
/// Mass, kg (> 0). A dynamic body without it has 1 kg.
struct Mass { double value = 1.0; };
/// Immovable when `value` is true: infinite mass, never integrated.
struct Static { bool value = true; };
/// Moved only by its own `Velocity` and `AngularVelocity` when `value` is
/// true (a moving platform, a spinning paddle): infinite mass, so neither
/// forces nor contacts change its motion, while it pushes and carries the
/// dynamic bodies it meets. Its velocity is its centre of mass's.
struct Kinematic { bool value = true; };
/// Circle shape of this radius, metres (> 0).
struct Radius { double value = 0.5; };
/// Box shape, full width and height in metres (> 0), rotated by `Angle`.
struct Box { double width = 1.0; double height = 1.0; };
/// Convex polygon shape: 3 to 8 vertices in metres relative to `Position`,
/// counter-clockwise, rotated by `Angle` about `Position`. Mass is spread
/// evenly, so the centre of mass is the polygon's centroid, which need not be
/// `Position`; `Velocity` is the centre of mass's. The loader refuses
/// non-convex, clockwise and degenerate lists (polygonProblem() says why).
struct Polygon {
    /// Default: a triangle whose centroid is its position (exact binary
    /// fractions, so it round-trips as written).
    std::vector<Vec2> vertices{{-0.5, -0.25}, {0.5, -0.25}, {0.0, 0.5}};
    /// Rounds the corners by this radius (metres, >= 0): the shape is the
    /// outline grown by a disc (Box2D's rounded polygons), and its mass
    /// includes the rounding. Absent is 0 and is not written on save.
    std::optional<double> radius;
};

/// Nothing when `vertices` is a valid polygon shape, else why not; the
/// error's `where` is the offending vertex's index, or empty for the whole
/// list. The loader, the world and the editor all ask this one function.
std::optional<Error> polygonProblem(const std::vector<Vec2>& vertices);

/// Area (m^2), centroid (metres, in the vertices' frame) and the second
/// moment of area about the centroid (m^4) of a valid polygon. Moment of
/// inertia for mass m is m * secondMoment / area.
struct PolygonMassProperties {
    double area = 0.0;
    Vec2 centroid;
    double secondMoment = 0.0;
};
PolygonMassProperties polygonMassProperties(const std::vector<Vec2>& vertices);
/// The same for the outline rounded by `radius` (the polygon grown by a
/// disc): the polygon, a rectangle r wide along each edge and a sector at
/// each corner; area A + P r + pi r^2. radius 0 gives polygonMassProperties
/// bit for bit.
PolygonMassProperties polygonMassProperties(const std::vector<Vec2>& vertices, double radius);

/// Capsule shape: the segment from `a` to `b` (metres, relative to
/// `Position`, rotated by `Angle` about it) swept by `radius`: a stadium.
/// Mass is spread evenly, so the centre of mass is the segment's midpoint,
/// which need not be `Position`; `Velocity` is the centre of mass's. The
/// loader refuses a == b (a circle is the shape for that).
struct Capsule {
    /// Default: a horizontal capsule 1.5 m long overall, centred on its
    /// position (exact binary fractions, so it round-trips as written).
    Vec2 a{-0.5, 0.0};
    Vec2 b{0.5, 0.0};
    double radius = 0.25;
};

/// Area (m^2) and moment of inertia per unit mass about the segment's
/// midpoint (m^2) of a capsule with core length `length` and `radius`:
/// a 2r by L rectangle plus two half discs.
struct CapsuleMassProperties {
    double area = 0.0;
    double inertiaPerMass = 0.0;
};
CapsuleMassProperties capsuleMassProperties(double length, double radius);

/// Chain shape: a polyline of segments in metres relative to `Position`
/// (rotated by `Angle` about it), closed from the last point back to the
/// first when `loop`. Smooth (a body sliding across a joint between two
/// segments feels no bump) and one-sided: it collides with bodies on the
/// right of each segment's direction, so a counter-clockwise loop keeps
/// bodies outside and a clockwise one inside. Only on a static body.
struct Chain {
    /// Default: a floor 4 m wide, drawn right to left so its solid side is up.
    std::vector<Vec2> points{{2.0, 0.0}, {-2.0, 0.0}};
    bool loop = false;
};

/// Most points a chain may have: a contact's feature id keeps the segment's
/// number in 10 bits (collisions.md).
inline constexpr std::size_t kMaxChainPoints = 1024;

/// Nothing when `points` (with `loop`) is a valid chain, else why not; the
/// error's `where` is the offending point's index, or empty for the whole
/// list. The loader, the world and the editor all ask this one function.
std::optional<Error> chainProblem(const std::vector<Vec2>& points, bool loop);
/// Why a chain is refused on a dynamic body (the loader's and the World's words).
inline constexpr const char* kChainOnDynamicBody =
    "a chain must be on a static or kinematic body (\"static\": true or \"kinematic\": true); a chain has no "
    "area, so it gives a dynamic body no mass or inertia to move by";

/// Orientation, radians, counter-clockwise.
struct Angle { double value = 0.0; };
/// Angular velocity, rad/s, counter-clockwise.
struct AngularVelocity { double value = 0.0; };
/// Display colour.
struct Color { Rgb value; };
/// Coefficient of restitution in [0, 1]; a pair uses the larger value.
/// Absent: 0 (no bounce).
struct Restitution { double value = 0.0; };
/// Coulomb friction coefficient (>= 0); a pair uses sqrt(f1*f2).
/// Absent: 0.2 (Box2D's default, so stacks stand without tuning).
struct Friction { double value = 0.2; };
/// Viscous damping coefficient b, kg/s: force -b*v.
struct Drag { double value = 0.0; };

/// The shape detects overlaps but never pushes when `value` is true: a
/// goal zone, a trigger. Bodies entering and leaving it are reported
/// (World::sensorEvents); nothing about any body's motion changes.
struct Sensor { bool value = true; };

/// The entity is a prefab, not simulated: every entity with the same
/// `value` (and the joints and springs among them) is one template that
/// emitters copy. No body, no contacts, no energy.
struct Template { std::string value; };

/// Adds a copy of template `templateName` at the entity's position every
/// `interval` seconds, up to `count` alive (the oldest removed first), each
/// with `velocity` turned by a random angle in +/- `spread` (world.seed),
/// removed `lifetime` seconds after it appeared when given. The last four
/// fields are the run's state, written by a save so that a resume is exact.
struct Emitter {
    std::string templateName;
    double interval = 1.0;               ///< s between copies, > 0
    int count = 10;                      ///< copies alive at most, >= 1
    Vec2 velocity;                       ///< m/s of each copy before the turn
    double spread = 0.0;                 ///< rad, each copy's velocity turned by a uniform angle in +/- spread
    std::optional<double> lifetime;      ///< s a copy lives; absent: until pushed out by count
    std::optional<double> next;          ///< s, world time of the next copy; absent: the world's time at build
    int emitted = 0;                     ///< copies this emitter made so far
    int alive = 0;                       ///< the newest `alive` of them are in the scene
    std::optional<double> oldest;        ///< s, when the oldest copy alive appeared
    /// The numbers N of its copies alive (named TEMPLATE#N), oldest first;
    /// empty: the `alive` numbers up to `emitted`, what a template's only
    /// emitter gives. Several emitters of one template share its numbers.
    std::vector<int> copies;
    friend bool operator==(const Emitter&, const Emitter&) = default;
};

/// The numbers of `em`'s copies alive, oldest first: Emitter::copies, or
/// when that is empty the newest `alive` numbers up to `emitted`.
inline std::vector<int> copyNumbers(const Emitter& em) {
    if (!em.copies.empty()) return em.copies;
    std::vector<int> numbers;
    for (int k = em.emitted - em.alive + 1; k <= em.emitted; ++k) numbers.push_back(k);
    return numbers;
}

/// Which pairs of shapes collide (Box2D's collision filter). Two shapes
/// with the same non-zero `group` always collide when it is positive and
/// never when it is negative; otherwise they collide when each one's
/// `category` bits meet the other's `mask` (shouldCollide). Absent: category
/// 1, every mask bit, group 0, which collides with everything that has no
/// filter.
struct Filter {
    std::uint32_t category = 1;           ///< the bits this shape is
    std::uint32_t mask = 0xFFFFFFFFu;     ///< the bits it collides with
    int group = 0;                        ///< same non-zero group: always (> 0) or never (< 0)
};

/// Box2D's rule for whether shapes with filters `a` and `b` collide.
inline bool shouldCollide(const Filter& a, const Filter& b) {
    if (a.group == b.group && a.group != 0) return a.group > 0;
    return (a.mask & b.category) != 0 && (a.category & b.mask) != 0;
}
inline bool operator==(const Filter& a, const Filter& b) {
    return a.category == b.category && a.mask == b.mask && a.group == b.group;
}

/// Infinite wall: bodies stay where dot(normal, p) >= offset (+ radius).
/// `normal` is unit length after loading.
struct Plane {
    Vec2 normal{0.0, 1.0};
    double offset = 0.0; ///< metres along the normal
};

/// One shape of a compound body (`Shapes`), in the body's frame: relative
/// to `Position`, turned with the body by `Angle`. The material, filter and
/// sensor fields, when given, replace the body's own for this shape.
struct CompoundShape {
    enum class Kind : std::uint8_t { Circle, Box, Polygon, Capsule };
    Kind kind = Kind::Circle;
    Vec2 center;                    ///< circle and box: the shape's centre, metres
    double radius = 0.5;            ///< circle and capsule, metres
    double width = 1.0, height = 1.0;  ///< box, metres
    double angle = 0.0;             ///< box: its turn in the body frame, rad
    std::vector<Vec2> vertices;     ///< polygon: 3 to 8, counter-clockwise, convex
    /// polygon: its corners rounded by this, metres (the item's "radius",
    /// as polygon.radius); absent = sharp
    std::optional<double> cornerRadius;
    Vec2 a{-0.5, 0.0}, b{0.5, 0.0}; ///< capsule: the segment's ends
    std::optional<double> density;  ///< kg/m^2; absent = 1
    std::optional<double> friction, restitution;
    std::optional<bool> sensor;
    std::optional<Filter> filter;
    friend bool operator==(const CompoundShape&, const CompoundShape&) = default;
};

/// A compound body: several shapes on one rigid body. Exclusive with the
/// single-shape components (radius, box, polygon, capsule, plane).
struct Shapes {
    /// Default: one circle of 0.5 m on the position, so adding the
    /// component (the editor's Add) gives a body that collides.
    std::vector<CompoundShape> items{CompoundShape{}};
};

/// Nothing when `shape` is a valid compound-body shape, else why not (the
/// error's `where` is the field inside the item).
std::optional<Error> compoundShapeProblem(const CompoundShape& shape);

/// Area (m^2) of one compound shape, its centroid in the body frame (m),
/// and its polar second moment of area about that centroid (m^4).
struct ShapeAreaProperties {
    double area = 0.0;
    Vec2 centroid;
    double secondMoment = 0.0;
};
ShapeAreaProperties compoundShapeArea(const CompoundShape& shape);

/// Mass properties of a compound body: each shape weighs density times
/// area; `mass`, when given, scales them all so they sum to it. Centre of
/// mass in the body frame (m); inertia about it (kg m^2, parallel axes);
/// each shape's mass (kg) in list order.
struct CompoundMassProperties {
    double mass = 0.0;
    Vec2 centre;
    double inertia = 0.0;
    std::vector<double> shapeMass;
};
CompoundMassProperties compoundMassProperties(const Shapes& shapes, std::optional<double> mass);

/// Whether the body-frame point `local` is inside compound shape `shape`
/// (picking).
bool compoundShapeContains(const CompoundShape& shape, Vec2 local);
/// The shape's outline as points in the body frame, and the radius swept
/// around them (circles and capsules): its extent at any turn of the body.
struct ShapeOutline {
    std::vector<Vec2> points;
    double radius = 0.0;
};
ShapeOutline compoundShapeOutline(const CompoundShape& shape);

/// Newtonian attractor: every other dynamic body i feels
/// G*m_i*m_a*r/(|r|^2+eps^2)^(3/2) towards it.
struct Attractor {
    double softening = 0.0; ///< eps, metres; removes the singularity at r = 0
};

/// Spring-damper between entities `a` and `b`, or between `a` and the fixed
/// world point `anchor` when `b` is null. Force on a:
/// -(k*(len-rest_length) + damping*(closing speed)) along the unit axis.
/// A spring entity has no body of its own. The ends are handles: files name
/// them, the loader resolves each name once and the saver writes the end's
/// current name, so renaming a body keeps its springs.
struct Spring {
    Entity a;
    Entity b;                      ///< null when anchored
    std::optional<Vec2> anchor;    ///< world point, metres
    double k = 100.0;              ///< stiffness, N/m (>= 0)
    double damping = 0.0;          ///< N*s/m along the axis (>= 0)
    /// Natural length, metres (>= 0). Absent in a file: the distance between
    /// the ends when the level is loaded.
    std::optional<double> restLength;
};

/// Flocking behaviour (Reynolds 1987) as proxy forces. All weights are
/// accelerations in m/s^2 per unit of steering; radii are metres.
struct Boid {
    double neighborRadius = 2.0;    ///< who counts as a neighbour
    double separationRadius = 0.8;  ///< closer than this: push apart
    double separation = 4.0;        ///< weight of pushing apart
    double alignment = 1.0;         ///< weight of matching neighbours' velocity
    double cohesion = 1.0;          ///< weight of moving to neighbours' centre
    std::optional<Vec2> goal;       ///< seek this point when set
    double goalWeight = 1.0;        ///< weight of seeking the goal
    double maxSpeed = 4.0;          ///< m/s; steering never exceeds it
};

/// A constraint between two bodies, or a body and the world
/// (docs/joints.md, "In a level file"). A joint entity has no body of its own. The
/// ends are entity handles, resolved from names when a file is loaded
/// (names are used only in files), so renaming a body keeps its joints.
/// After loading, `anchor` is consumed (turned into the locals) and
/// `reference_angle` / `length` hold their defaults, so a save writes what
/// the simulation uses.
struct Joint {
    /// "hinge", "slider", "weld", "distance", "rope" or "wheel" (jointTypeNames()).
    std::string type;
    Entity a;                       ///< first body; required
    Entity b;                       ///< second body; null = the world
    Vec2 localA;                    ///< anchor in a's frame (relative to its position), metres
    Vec2 localB;                    ///< anchor in b's frame; a world point when b is the world
    std::optional<Vec2> anchor;     ///< input only: one world point that sets both locals
    std::optional<Vec2> axis;       ///< slider, wheel: direction of travel in a's frame; absent = {1, 0}
    /// Angle of b relative to a that counts as zero (hinge limits, slider,
    /// weld), radians. Absent in a file: the relative angle at first load.
    std::optional<double> referenceAngle;
    std::optional<double> lower;    ///< hinge: rad; slider, wheel: m. Absent: no lower limit
    std::optional<double> upper;    ///< hinge: rad; slider, wheel: m. Absent: no upper limit
    std::optional<double> motorSpeed;     ///< hinge rad/s, slider m/s; absent = 0 (a brake)
    std::optional<double> maxMotorTorque; ///< hinge and wheel motor, N*m; absent: no motor
    std::optional<double> maxMotorForce;  ///< slider motor, N; absent: no motor
    /// distance and rope: metres. Absent in a file: the anchors' distance at first load.
    std::optional<double> length;
    /// weld, distance: spring frequency, Hz; absent or 0 = rigid. wheel: the
    /// suspension spring along the axis (rest: anchors together); absent or
    /// 0 = none, free travel.
    std::optional<double> stiffnessHz;
    std::optional<double> dampingRatio;   ///< weld, distance, wheel: with stiffness_hz; absent = 1 (critical)
    /// hinge: a rotational spring toward reference_angle of this frequency,
    /// Hz (Box2D's revolute spring); absent or 0 = no spring.
    std::optional<double> springHz;
    std::optional<double> springDampingRatio;  ///< hinge spring's damping ratio; absent = 1 (critical)
    /// Any type: the joint breaks (is removed from the run) after a step
    /// whose constraint force exceeds this, newtons (> 0); absent: never.
    std::optional<double> maxForce;
    bool collideConnected = false;        ///< whether a and b still collide with each other
};

/// Joint type names in file order: hinge, slider, weld, distance, rope, wheel.
std::span<const std::string_view> jointTypeNames();

} // namespace stepwise
