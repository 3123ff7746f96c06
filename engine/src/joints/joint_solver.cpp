// Joint constraints in the soft-step solver. See joint_solver.hpp; the
// formulas are the ones of Catto's "Solver2D" notes and Box2D v3's joint
// solvers (soft constraints with a bias rate, mass scale and impulse scale
// from the stiffness and the substep), written for this engine's bodies.

#include "joints/joint_solver.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace stepwise::joints {

using collision::Rot;
using collision::Softness;
using collision::SolverBody;
using collision::crossSV;
using collision::rotate;

namespace {

/// Angle of a rotation, rad. Rotations within one step stay well inside
/// (-pi, pi), so this recovers the turn since step start exactly enough.
inline double angleOf(Rot q) { return std::atan2(q.s, q.c); }
inline Vec2 leftPerp(Vec2 v) { return {-v.y, v.x}; }

/// Solves [k11 k12; k12 k22] x = b; a singular K gives 0 (no impulse).
inline Vec2 solve22(double k11, double k12, double k22, Vec2 b) {
    double det = k11 * k22 - k12 * k12;
    if (det != 0.0) det = 1.0 / det;
    return {det * (k22 * b.x - k12 * b.y), det * (k11 * b.y - k12 * b.x)};
}

/// Velocities of the two bodies, worked on locally and stored once (A and B
/// never alias except when both are the static body 0, whose masses are 0).
struct Pair {
    Vec2 vA, vB;
    double wA, wB;
    double mA, mB, iA, iB;
    explicit Pair(const SolverBody& a, const SolverBody& b)
        : vA(a.v), vB(b.v), wA(a.w), wB(b.w), mA(a.invMass), mB(b.invMass), iA(a.invInertia), iB(b.invInertia) {}
    void store(SolverBody& a, SolverBody& b) const {
        a.v = vA;
        a.w = wA;
        b.v = vB;
        b.w = wB;
    }
    /// Impulse p at anchors rA, rB: -p on A, +p on B.
    void applyLinear(Vec2 p, Vec2 rA, Vec2 rB) {
        vA -= mA * p;
        wA -= iA * cross(rA, p);
        vB += mB * p;
        wB += iB * cross(rB, p);
    }
    void applyAngular(double impulse) {
        wA -= iA * impulse;
        wB += iB * impulse;
    }
};

/// Bias, mass scale and impulse scale of one row: a speculative row (C > 0
/// for a one-sided limit) may close its gap within the substep; otherwise
/// the soft correction applies in biased passes only.
struct Row {
    double bias = 0.0, massScale = 1.0, impulseScale = 0.0;
};
inline Row limitRow(double C, double invH, const Softness& soft, bool useBias) {
    Row r;
    if (C > 0.0) r.bias = C * invH;
    else if (useBias) r = {soft.biasRate * C, soft.massScale, soft.impulseScale};
    return r;
}
inline Row equalityRow(double C, const Softness& soft, bool apply) {
    return apply ? Row{soft.biasRate * C, soft.massScale, soft.impulseScale} : Row{};
}

/// Hinge or weld point constraint: the anchors coincide (2x2 solve).
void solvePoint(JointConstraint& j, const SolverBody& a, const SolverBody& b, Pair& p, const Softness& soft,
                bool apply) {
    const Vec2 rA = rotate(a.dq, j.anchorA), rB = rotate(b.dq, j.anchorB);
    const Vec2 cdot = p.vB + crossSV(p.wB, rB) - p.vA - crossSV(p.wA, rA);
    const Vec2 separation = (b.dp - a.dp) + (rB - rA) + j.deltaCenter;
    const Row row = equalityRow(0.0, soft, apply);
    const Vec2 bias = apply ? soft.biasRate * separation : Vec2{};
    const double mSum = p.mA + p.mB;
    const double k11 = mSum + rA.y * rA.y * p.iA + rB.y * rB.y * p.iB;
    const double k12 = -rA.y * rA.x * p.iA - rB.y * rB.x * p.iB;
    const double k22 = mSum + rA.x * rA.x * p.iA + rB.x * rB.x * p.iB;
    const Vec2 x = solve22(k11, k12, k22, cdot + bias);
    const Vec2 impulse = -row.massScale * x - row.impulseScale * j.linearImpulse;
    j.linearImpulse += impulse;
    p.applyLinear(impulse, rA, rB);
}

/// The rotational spring, one-sided angular limits and the motor of a hinge
/// (axial rows).
void solveHingeAxial(JointConstraint& j, const SolverBody& a, const SolverBody& b, Pair& p, double h,
                     const Softness& soft, bool useBias) {
    // The joint's angle (two atan2), once for its spring and its limits: a
    // ragdoll's hinges have both.
    const bool limited = j.hasLower || j.hasUpper;
    const double angle = j.spring || limited ? j.deltaAngle + angleOf(b.dq) - angleOf(a.dq) : 0.0;
    if (j.spring) {
        // Box2D v3's revolute spring: a soft row toward the reference angle
        // on the axial mass, in both passes (it is a force, not an error to
        // correct, so the relax pass must not drop it). With the soft step's
        // mass and impulse scales this is the implicit spring-damper of
        // frequency springHz on the joint's relative rotation.
        const Softness spring = Softness::make(j.springHz, j.springDampingRatio, h);
        const double cdot = p.wB - p.wA;
        const double impulse = -j.axialMass * spring.massScale * (cdot + spring.biasRate * angle) -
                               spring.impulseScale * j.springImpulse;
        j.springImpulse += impulse;
        p.applyAngular(impulse);
    }
    if (j.motor) {
        const double cdot = p.wB - p.wA - j.motorSpeed;
        const double maxImpulse = j.maxMotor * h;
        const double old = j.motorImpulse;
        j.motorImpulse = std::clamp(old - j.axialMass * cdot, -maxImpulse, maxImpulse);
        p.applyAngular(j.motorImpulse - old);
    }
    if (!limited) return;
    const double invH = 1.0 / h;
    if (j.hasLower) {
        const Row r = limitRow(angle - j.lower, invH, soft, useBias);
        const double cdot = p.wB - p.wA;
        const double impulse = -j.axialMass * r.massScale * (cdot + r.bias) - r.impulseScale * j.lowerImpulse;
        const double total = std::max(j.lowerImpulse + impulse, 0.0);
        p.applyAngular(total - j.lowerImpulse);
        j.lowerImpulse = total;
    }
    if (j.hasUpper) {
        const Row r = limitRow(j.upper - angle, invH, soft, useBias);
        const double cdot = p.wA - p.wB;
        const double impulse = -j.axialMass * r.massScale * (cdot + r.bias) - r.impulseScale * j.upperImpulse;
        const double total = std::max(j.upperImpulse + impulse, 0.0);
        p.applyAngular(-(total - j.upperImpulse));
        j.upperImpulse = total;
    }
}

void solveWeld(JointConstraint& j, const SolverBody& a, const SolverBody& b, Pair& p, double h,
               const Softness& soft, bool useBias) {
    // A weld with stiffness is a spring in both passes; a rigid one is
    // corrected softly in the biased passes only.
    const bool spring = j.stiffnessHz > 0.0;
    const Softness s = spring ? Softness::make(j.stiffnessHz, j.dampingRatio, h) : soft;
    const bool apply = spring || useBias;
    const double angle = j.deltaAngle + angleOf(b.dq) - angleOf(a.dq);
    const Row r = equalityRow(angle, s, apply);
    const double cdot = p.wB - p.wA;
    const double impulse = -j.axialMass * r.massScale * (cdot + r.bias) - r.impulseScale * j.angularImpulse;
    j.angularImpulse += impulse;
    p.applyAngular(impulse);
    solvePoint(j, a, b, p, s, apply);
}

/// Distance (two-sided, rigid or spring) and rope (at most `length`).
void solveDistance(JointConstraint& j, const SolverBody& a, const SolverBody& b, Pair& p, double h,
                   const Softness& soft, bool useBias) {
    const Vec2 rA = rotate(a.dq, j.anchorA), rB = rotate(b.dq, j.anchorB);
    const Vec2 d = (b.dp - a.dp) + j.deltaCenter + (rB - rA);
    const double len = length(d);
    if (!(len > 1e-12)) return;  // coincident anchors: no direction to push along
    const Vec2 axis = (1.0 / len) * d;
    const double crA = cross(rA, axis), crB = cross(rB, axis);
    const double k = p.mA + p.mB + p.iA * crA * crA + p.iB * crB * crB;
    const double mass = k > 0.0 ? 1.0 / k : 0.0;
    const Vec2 vr = p.vB + crossSV(p.wB, rB) - p.vA - crossSV(p.wA, rA);
    const double cdot = dot(axis, vr);
    if (j.kind == JointKind::Distance) {
        const bool spring = j.stiffnessHz > 0.0;
        const Row r = spring ? equalityRow(len - j.length, Softness::make(j.stiffnessHz, j.dampingRatio, h), true)
                             : equalityRow(len - j.length, soft, useBias);
        const double impulse = -mass * r.massScale * (cdot + r.bias) - r.impulseScale * j.axialImpulse;
        j.axialImpulse += impulse;
        p.applyLinear(impulse * axis, rA, rB);
        return;
    }
    // Rope: only pulls, when the anchors are `length` apart or more.
    const Row r = limitRow(j.length - len, 1.0 / h, soft, useBias);
    const double impulse = -mass * r.massScale * (-cdot + r.bias) - r.impulseScale * j.upperImpulse;
    const double total = std::max(j.upperImpulse + impulse, 0.0);
    p.applyLinear(-(total - j.upperImpulse) * axis, rA, rB);
    j.upperImpulse = total;
}

/// What a slider's and a wheel's rows share: the arms rA, rB and the
/// anchors' offset d (metres), a's axis, the travel along it, and the
/// effective mass along it (kg).
struct AxisFrame {
    Vec2 rA, rB, d, axis;
    double translation = 0.0, a1 = 0.0, a2 = 0.0, axialMass = 0.0;
    AxisFrame(const JointConstraint& j, const SolverBody& a, const SolverBody& b, const Pair& p)
        : rA(rotate(a.dq, j.anchorA)), rB(rotate(b.dq, j.anchorB)),
          d((b.dp - a.dp) + j.deltaCenter + (rB - rA)), axis(rotate(a.dq, j.axisA)) {
        translation = dot(axis, d);
        a1 = cross(d + rA, axis);
        a2 = cross(rB, axis);
        const double k = p.mA + p.mB + p.iA * a1 * a1 + p.iB * a2 * a2;
        axialMass = k > 0.0 ? 1.0 / k : 0.0;
    }
    /// Relative speed along the axis, m/s.
    double speed(const Pair& p) const { return dot(axis, p.vB - p.vA) + a2 * p.wB - a1 * p.wA; }
    /// An impulse along the axis (N s): -on A, +on B.
    void apply(Pair& p, double impulse) const {
        p.vA -= (p.mA * impulse) * axis;
        p.wA -= p.iA * impulse * a1;
        p.vB += (p.mB * impulse) * axis;
        p.wB += p.iB * impulse * a2;
    }
};

/// A slider's or wheel's travel limits along its axis: one-sided rows on
/// the translation, lower then upper.
void solveTravelLimits(JointConstraint& j, const AxisFrame& f, Pair& p, double invH, const Softness& soft,
                       bool useBias) {
    if (j.hasLower) {
        const Row r = limitRow(f.translation - j.lower, invH, soft, useBias);
        const double impulse = -f.axialMass * r.massScale * (f.speed(p) + r.bias) - r.impulseScale * j.lowerImpulse;
        const double total = std::max(j.lowerImpulse + impulse, 0.0);
        f.apply(p, total - j.lowerImpulse);
        j.lowerImpulse = total;
    }
    if (j.hasUpper) {
        const Row r = limitRow(j.upper - f.translation, invH, soft, useBias);
        const double impulse = -f.axialMass * r.massScale * (-f.speed(p) + r.bias) - r.impulseScale * j.upperImpulse;
        const double total = std::max(j.upperImpulse + impulse, 0.0);
        f.apply(p, -(total - j.upperImpulse));
        j.upperImpulse = total;
    }
}

void solveSlider(JointConstraint& j, const SolverBody& a, const SolverBody& b, Pair& p, double h,
                 const Softness& soft, bool useBias) {
    const AxisFrame f(j, a, b, p);
    if (j.motor) {
        const double maxImpulse = j.maxMotor * h;
        const double old = j.motorImpulse;
        j.motorImpulse = std::clamp(old + f.axialMass * (j.motorSpeed - f.speed(p)), -maxImpulse, maxImpulse);
        f.apply(p, j.motorImpulse - old);
    }
    solveTravelLimits(j, f, p, 1.0 / h, soft, useBias);
    // No sideways travel and no relative rotation, solved together.
    const Vec2 perp = leftPerp(f.axis);
    const double s1 = cross(f.d + f.rA, perp), s2 = cross(f.rB, perp);
    const Vec2 cdot{dot(perp, p.vB - p.vA) + s2 * p.wB - s1 * p.wA, p.wB - p.wA};
    Vec2 bias;
    Row r;
    if (useBias) {
        const Vec2 C{dot(perp, f.d), j.deltaAngle + angleOf(b.dq) - angleOf(a.dq)};
        bias = soft.biasRate * C;
        r = {0.0, soft.massScale, soft.impulseScale};
    }
    const double k11 = p.mA + p.mB + p.iA * s1 * s1 + p.iB * s2 * s2;
    const double k12 = p.iA * s1 + p.iB * s2;
    double k22 = p.iA + p.iB;
    if (k22 == 0.0) k22 = 1.0;  // two bodies that cannot turn: the angle row is inert
    const Vec2 x = solve22(k11, k12, k22, cdot + bias);
    const Vec2 impulse = -r.massScale * x - r.impulseScale * j.linearImpulse;
    j.linearImpulse += impulse;
    const Vec2 P = impulse.x * perp;
    p.vA -= p.mA * P;
    p.wA -= p.iA * (impulse.x * s1 + impulse.y);
    p.vB += p.mB * P;
    p.wB += p.iB * (impulse.x * s2 + impulse.y);
}

/// Wheel (Box2D v3's wheel joint): b's anchor stays on the line through
/// a's anchor along a's axis (one row, rigid and softly corrected like the
/// other rigid rows), travels along it against a spring (stiffnessHz,
/// dampingRatio, rest where the anchors coincide; none at 0 Hz) and within
/// the travel limits, and turns freely but for the motor.
void solveWheel(JointConstraint& j, const SolverBody& a, const SolverBody& b, Pair& p, double h,
                const Softness& soft, bool useBias) {
    if (j.motor) {
        const double cdot = p.wB - p.wA - j.motorSpeed;
        const double maxImpulse = j.maxMotor * h;
        const double old = j.motorImpulse;
        j.motorImpulse = std::clamp(old - j.axialMass * cdot, -maxImpulse, maxImpulse);
        p.applyAngular(j.motorImpulse - old);
    }
    const AxisFrame f(j, a, b, p);
    if (j.spring) {
        // A force in both passes, as the hinge's spring.
        const Softness spring = Softness::make(j.stiffnessHz, j.dampingRatio, h);
        const double impulse = -f.axialMass * spring.massScale * (f.speed(p) + spring.biasRate * f.translation) -
                               spring.impulseScale * j.springImpulse;
        j.springImpulse += impulse;
        f.apply(p, impulse);
    }
    solveTravelLimits(j, f, p, 1.0 / h, soft, useBias);
    // The point stays on the line: no travel across the axis.
    const Vec2 perp = leftPerp(f.axis);
    const double s1 = cross(f.d + f.rA, perp), s2 = cross(f.rB, perp);
    const double kp = p.mA + p.mB + p.iA * s1 * s1 + p.iB * s2 * s2;
    const double perpMass = kp > 0.0 ? 1.0 / kp : 0.0;
    const Row r = equalityRow(dot(perp, f.d), soft, useBias);
    const double cdot = dot(perp, p.vB - p.vA) + s2 * p.wB - s1 * p.wA;
    const double impulse = -perpMass * r.massScale * (cdot + r.bias) - r.impulseScale * j.linearImpulse.x;
    j.linearImpulse.x += impulse;
    p.vA -= (p.mA * impulse) * perp;
    p.wA -= p.iA * impulse * s1;
    p.vB += (p.mB * impulse) * perp;
    p.wB += p.iB * impulse * s2;
}

} // namespace

JointImpulse impulsesOf(const JointConstraint& j) {
    // The hinge's spring travels as `angular` and the wheel's as `axial`,
    // rows those types do not otherwise have: files keep one set of keys.
    JointImpulse out{j.entity,       j.linearImpulse, j.angularImpulse, j.axialImpulse, j.motorImpulse,
                     j.lowerImpulse, j.upperImpulse};
    if (j.kind == JointKind::Hinge) out.angular = j.springImpulse;
    if (j.kind == JointKind::Wheel) out.axial = j.springImpulse;
    return out;
}

void setImpulses(JointConstraint& j, const JointImpulse& in) {
    const bool hingeLike = j.kind == JointKind::Hinge || j.kind == JointKind::Slider;
    j.linearImpulse = hingeLike || j.kind == JointKind::Weld ? in.linear : Vec2{};
    j.angularImpulse = j.kind == JointKind::Weld ? in.angular : 0.0;
    j.axialImpulse = j.kind == JointKind::Distance ? in.axial : 0.0;
    j.motorImpulse = hingeLike && j.motor ? in.motor : 0.0;
    j.lowerImpulse = hingeLike && j.hasLower ? in.lower : 0.0;
    j.upperImpulse = (hingeLike && j.hasUpper) || j.kind == JointKind::Rope ? in.upper : 0.0;
    j.springImpulse = !j.spring                  ? 0.0
                      : j.kind == JointKind::Hinge ? in.angular
                                                   : in.axial;
    if (j.kind == JointKind::Wheel) {
        j.linearImpulse = {in.linear.x, 0.0};
        j.motorImpulse = j.motor ? in.motor : 0.0;
        j.lowerImpulse = j.hasLower ? in.lower : 0.0;
        j.upperImpulse = j.hasUpper ? in.upper : 0.0;
    }
}

void takeBackJointImpulses(std::span<JointConstraint> joints, std::span<const std::uint32_t> marked,
                           std::span<const JointImpulse> saved, std::span<SolverBody> bodies) {
    for (std::size_t m = 0; m < marked.size(); ++m) {
        JointConstraint& j = joints[marked[m]];
        const JointImpulse now = impulsesOf(j), before = saved[m];
        const JointImpulse back{j.entity,           before.linear - now.linear, before.angular - now.angular,
                                before.axial - now.axial, before.motor - now.motor, before.lower - now.lower,
                                before.upper - now.upper};
        // The warm start applies a joint's impulses with its geometry; on a
        // copy holding the gain's opposite it takes the gain back.
        JointConstraint undo = j;
        setImpulses(undo, back);
        const std::uint32_t only = 0;
        warmStartJoints(std::span<JointConstraint>(&undo, 1), std::span<const std::uint32_t>(&only, 1), bodies);
        setImpulses(j, before);
    }
}

namespace {

/// The joint's centres, anchors and angles from its bodies' centres and
/// angles (per collider).
void poseJoint(JointConstraint& j, std::span<const Vec2> centres, std::span<const double> angles) {
    const auto pose = [&](const JointEnd& e, Vec2& centre, double& angle) {
        centre = e.collider >= 0 ? centres[std::size_t(e.collider)] : e.fixedCentre;
        angle = e.collider >= 0 ? angles[std::size_t(e.collider)] : e.fixedAngle;
    };
    double angleA = 0.0, angleB = 0.0;
    pose(j.a, j.centreA, angleA);
    pose(j.b, j.centreB, angleB);
    const Rot qA = Rot::fromAngle(angleA), qB = Rot::fromAngle(angleB);
    j.anchorA = rotate(qA, j.a.local);
    j.anchorB = rotate(qB, j.b.local);
    j.deltaCenter = j.centreB - j.centreA;
    j.deltaAngle = angleB - angleA - j.referenceAngle;
    j.axisA = rotate(qA, j.localAxis);
}

} // namespace

void prepareJoints(std::span<JointConstraint> joints, std::span<const SolverBody> bodies,
                   std::span<const Vec2> centres, std::span<const double> angles) {
    for (JointConstraint& j : joints) {
        if (j.asleep) continue;  // its island sleeps: nothing moves it
        poseJoint(j, centres, angles);
        const double k = bodies[j.a.solverBody].invInertia + bodies[j.b.solverBody].invInertia;
        j.axialMass = k > 0.0 ? 1.0 / k : 0.0;
    }
}

void poseResting(std::span<JointConstraint> joints, std::span<const Vec2> centres, std::span<const double> angles) {
    for (JointConstraint& j : joints)
        if (j.asleep && !j.broken) poseJoint(j, centres, angles);
}

void colourJoints(std::span<const JointConstraint> joints, std::size_t bodyCount, std::vector<std::uint32_t>& order,
                  std::vector<std::uint32_t>* colourEnds) {
    constexpr int kColours = 64;
    std::vector<std::uint64_t> used(bodyCount, 0);
    constexpr std::uint8_t kNone = 255;
    std::vector<std::uint8_t> colourOf(joints.size());
    // start[c + 1]: where colour c begins once summed (the overflow is colour kColours).
    std::uint32_t start[kColours + 3] = {};
    // A broken joint is left out (every pass skips it): the joints still
    // whole are coloured as a level saved after the break would colour them,
    // so a run resumed from that save visits them in the same order.
    for (std::size_t k = 0; k < joints.size(); ++k) {
        if (joints[k].broken) {
            colourOf[k] = kNone;
            continue;
        }
        const std::uint32_t a = joints[k].a.solverBody, b = joints[k].b.solverBody;
        const std::uint64_t free = ~((a != 0 ? used[a] : 0) | (b != 0 ? used[b] : 0));
        const int colour = free != 0 ? std::countr_zero(free) : kColours;
        if (colour < kColours) {
            if (a != 0) used[a] |= std::uint64_t(1) << colour;
            if (b != 0) used[b] |= std::uint64_t(1) << colour;
        }
        colourOf[k] = std::uint8_t(colour);
        ++start[colour + 2];
    }
    // A stable counting sort by colour.
    for (int c = 2; c < kColours + 3; ++c) start[c] += start[c - 1];
    order.resize(start[kColours + 2]);
    for (std::size_t k = 0; k < joints.size(); ++k)
        if (colourOf[k] != kNone) order[start[colourOf[k] + 1]++] = std::uint32_t(k);
    // Each colour's end is now where the next one began.
    if (colourEnds) colourEnds->assign(start + 1, start + kColours + 2);
}

void warmStartJoints(std::span<JointConstraint> joints, std::span<const std::uint32_t> order,
                     std::span<SolverBody> bodies) {
    for (const std::uint32_t k : order) {
        JointConstraint& j = joints[k];
        if (j.asleep) continue;
        SolverBody& a = bodies[j.a.solverBody];
        SolverBody& b = bodies[j.b.solverBody];
        Pair p(a, b);
        const Vec2 rA = rotate(a.dq, j.anchorA), rB = rotate(b.dq, j.anchorB);
        switch (j.kind) {
        case JointKind::Hinge:
        case JointKind::Weld: {
            double axial = j.kind == JointKind::Weld ? j.angularImpulse
                                                     : j.motorImpulse + j.lowerImpulse - j.upperImpulse;
            // Only a hinge with a spring adds it: 0 + x could turn a -0 into
            // +0 and change the bits of a level without springs.
            if (j.spring) axial += j.springImpulse;
            p.applyLinear(j.linearImpulse, rA, rB);
            p.applyAngular(axial);
            break;
        }
        case JointKind::Slider: {
            const Vec2 d = (b.dp - a.dp) + j.deltaCenter + (rB - rA);
            const Vec2 axis = rotate(a.dq, j.axisA), perp = leftPerp(axis);
            const double axial = j.motorImpulse + j.lowerImpulse - j.upperImpulse;
            const Vec2 P = axial * axis + j.linearImpulse.x * perp;
            p.vA -= p.mA * P;
            p.wA -= p.iA * (axial * cross(d + rA, axis) + j.linearImpulse.x * cross(d + rA, perp) + j.linearImpulse.y);
            p.vB += p.mB * P;
            p.wB += p.iB * (axial * cross(rB, axis) + j.linearImpulse.x * cross(rB, perp) + j.linearImpulse.y);
            break;
        }
        case JointKind::Wheel: {
            const Vec2 d = (b.dp - a.dp) + j.deltaCenter + (rB - rA);
            const Vec2 axis = rotate(a.dq, j.axisA), perp = leftPerp(axis);
            const double axial = j.springImpulse + j.lowerImpulse - j.upperImpulse;
            const Vec2 P = axial * axis + j.linearImpulse.x * perp;
            p.vA -= p.mA * P;
            p.wA -= p.iA * (axial * cross(d + rA, axis) + j.linearImpulse.x * cross(d + rA, perp) + j.motorImpulse);
            p.vB += p.mB * P;
            p.wB += p.iB * (axial * cross(rB, axis) + j.linearImpulse.x * cross(rB, perp) + j.motorImpulse);
            break;
        }
        case JointKind::Distance:
        case JointKind::Rope: {
            const Vec2 d = (b.dp - a.dp) + j.deltaCenter + (rB - rA);
            const double len = length(d);
            if (!(len > 1e-12)) break;
            p.applyLinear((j.axialImpulse - j.upperImpulse) / len * d, rA, rB);
            break;
        }
        }
        p.store(a, b);
    }
}

void solveJoints(std::span<JointConstraint> joints, std::span<const std::uint32_t> order, std::span<SolverBody> bodies,
                 double h, const Softness& loopSoft, const Softness& directSoft, bool useBias) {
    for (const std::uint32_t k : order) {
        JointConstraint& j = joints[k];
        if (j.asleep) continue;
        const Softness& soft = j.direct ? directSoft : loopSoft;
        SolverBody& a = bodies[j.a.solverBody];
        SolverBody& b = bodies[j.b.solverBody];
        Pair p(a, b);
        switch (j.kind) {
        case JointKind::Hinge:
            solveHingeAxial(j, a, b, p, h, soft, useBias);
            if (!j.direct) solvePoint(j, a, b, p, soft, useBias);
            break;
        case JointKind::Weld:
            if (!j.direct) solveWeld(j, a, b, p, h, soft, useBias);
            break;
        case JointKind::Slider: solveSlider(j, a, b, p, h, soft, useBias); break;
        case JointKind::Wheel: solveWheel(j, a, b, p, h, soft, useBias); break;
        case JointKind::Distance:
        case JointKind::Rope: solveDistance(j, a, b, p, h, soft, useBias); break;
        }
        p.store(a, b);
    }
}

void stiffenRotation(std::span<const JointConstraint> joints, std::span<SolverBody> bodies, double h,
                     std::vector<std::pair<std::uint32_t, double>>& saved, std::vector<double>& scratch) {
    // One pass over the joints sums h (r . impulse) per body in `scratch`
    // (kept all zero between calls) and lists each body at its first touch
    // (in joint order: deterministic); one pass over those bodies applies it.
    saved.clear();
    if (scratch.size() != bodies.size()) scratch.assign(bodies.size(), 0.0);
    const auto add = [&](std::uint32_t body, double k) {
        if (body == 0 || !(bodies[body].invInertia > 0.0)) return;
        if (scratch[body] == 0.0) saved.emplace_back(body, bodies[body].invInertia);
        // A sum that lands on exactly 0 would list the body again; nudging
        // it keeps the list unique (1e-300 kg m^2 changes no inertia).
        scratch[body] += k;
        if (scratch[body] == 0.0) scratch[body] = 1e-300;
    };
    for (const JointConstraint& j : joints) {
        if (j.asleep || (j.kind != JointKind::Hinge && j.kind != JointKind::Weld)) continue;
        // The impulse acts +linearImpulse on b at its anchor, - on a.
        add(j.a.solverBody, -h * dot(rotate(bodies[j.a.solverBody].dq, j.anchorA), j.linearImpulse));
        add(j.b.solverBody, h * dot(rotate(bodies[j.b.solverBody].dq, j.anchorB), j.linearImpulse));
    }
    for (const auto& [body, invI] : saved) {
        const double k = scratch[body];  // h^2 k, kg m^2
        scratch[body] = 0.0;
        if (k > 0.0) bodies[body].invInertia = 1.0 / (1.0 / invI + k);
    }
}

void restoreInertia(std::span<SolverBody> bodies, std::span<const std::pair<std::uint32_t, double>> saved) {
    for (const auto& [body, invI] : saved) bodies[body].invInertia = invI;
}

double jointAngle(const JointConstraint& j, std::span<const SolverBody> bodies) {
    return j.deltaAngle + angleOf(bodies[j.b.solverBody].dq) - angleOf(bodies[j.a.solverBody].dq);
}

JointAnchors jointAnchors(const JointConstraint& j, std::span<const SolverBody> bodies) {
    const SolverBody& a = bodies[j.a.solverBody];
    const SolverBody& b = bodies[j.b.solverBody];
    JointAnchors out;
    out.a = j.centreA + a.dp + rotate(a.dq, j.anchorA);
    out.b = j.centreB + b.dp + rotate(b.dq, j.anchorB);
    out.separation = length(out.b - out.a);
    return out;
}

JointAnchors restingAnchors(const JointConstraint& j) {
    JointAnchors out;
    out.a = j.centreA + j.anchorA;
    out.b = j.centreB + j.anchorB;
    out.separation = length(out.b - out.a);
    return out;
}

Vec2 jointForce(const JointConstraint& j, double h) {
    const double invH = h > 0.0 ? 1.0 / h : 0.0;
    switch (j.kind) {
    case JointKind::Hinge:
    case JointKind::Weld: return invH * j.linearImpulse;
    case JointKind::Slider: {
        const double axial = j.motorImpulse + j.lowerImpulse - j.upperImpulse;
        return invH * (axial * j.axisA + j.linearImpulse.x * leftPerp(j.axisA));
    }
    case JointKind::Wheel: {
        const double axial = j.springImpulse + j.lowerImpulse - j.upperImpulse;
        return invH * (axial * j.axisA + j.linearImpulse.x * leftPerp(j.axisA));
    }
    case JointKind::Distance:
    case JointKind::Rope: {
        const Vec2 d = j.deltaCenter + (j.anchorB - j.anchorA);
        const double len = length(d);
        return len > 1e-12 ? (invH * (j.axialImpulse - j.upperImpulse) / len) * d : Vec2{};
    }
    }
    return {};
}

double jointTorque(const JointConstraint& j, double h) {
    const double invH = h > 0.0 ? 1.0 / h : 0.0;
    switch (j.kind) {
    case JointKind::Hinge: {
        double axial = j.motorImpulse + j.lowerImpulse - j.upperImpulse;
        if (j.spring) axial += j.springImpulse;
        return invH * axial;
    }
    case JointKind::Weld: return invH * j.angularImpulse;
    case JointKind::Slider: return invH * j.linearImpulse.y;
    case JointKind::Wheel: return invH * j.motorImpulse;
    default: return 0.0;
    }
}

} // namespace stepwise::joints
