#include "scene_bounds.hpp"

#include "stepwise/components.hpp"

#include <cmath>

namespace stepwise::render {

std::optional<ShapeBox> shapeBox(const Scene& scene, Entity e) {
    const Position* p = scene.registry.tryGet<Position>(e);
    if (!p) return std::nullopt;
    if (const Radius* r = scene.registry.tryGet<Radius>(e)) return ShapeBox{p->value, Vec2{r->value, r->value}};
    const Angle* a = scene.registry.tryGet<Angle>(e);
    const double angle = a ? a->value : 0.0;
    if (const Box* b = scene.registry.tryGet<Box>(e)) {
        const double c = std::abs(std::cos(angle)), s = std::abs(std::sin(angle));
        return ShapeBox{p->value, Vec2{0.5 * (c * b->width + s * b->height), 0.5 * (s * b->width + c * b->height)}};
    }
    if (const Polygon* poly = scene.registry.tryGet<Polygon>(e); poly && !poly->vertices.empty()) {
        const double c = std::cos(angle), s = std::sin(angle);
        Bounds bounds;
        for (const Vec2 v : poly->vertices) bounds.add(p->value + Vec2{c * v.x - s * v.y, s * v.x + c * v.y});
        const double r = poly->radius.value_or(0.0);
        return ShapeBox{0.5 * (bounds.lo + bounds.hi), 0.5 * (bounds.hi - bounds.lo) + Vec2{r, r}};
    }
    if (const Capsule* cap = scene.registry.tryGet<Capsule>(e)) {
        const double c = std::cos(angle), s = std::sin(angle);
        const Vec2 ea = p->value + Vec2{c * cap->a.x - s * cap->a.y, s * cap->a.x + c * cap->a.y};
        const Vec2 eb = p->value + Vec2{c * cap->b.x - s * cap->b.y, s * cap->b.x + c * cap->b.y};
        return ShapeBox{0.5 * (ea + eb), Vec2{0.5 * std::abs(eb.x - ea.x) + cap->radius, 0.5 * std::abs(eb.y - ea.y) + cap->radius}};
    }
    if (const Shapes* shapes = scene.registry.tryGet<Shapes>(e); shapes && !shapes->items.empty()) {
        const double c = std::cos(angle), s = std::sin(angle);
        Bounds bounds;
        for (const CompoundShape& shape : shapes->items) {
            const ShapeOutline outline = compoundShapeOutline(shape);
            const Vec2 r{outline.radius, outline.radius};
            for (const Vec2 v : outline.points) {
                const Vec2 w = p->value + Vec2{c * v.x - s * v.y, s * v.x + c * v.y};
                bounds.add(w - r);
                bounds.add(w + r);
            }
        }
        return ShapeBox{0.5 * (bounds.lo + bounds.hi), 0.5 * (bounds.hi - bounds.lo)};
    }
    if (const Chain* chain = scene.registry.tryGet<Chain>(e); chain && !chain->points.empty()) {
        const double c = std::cos(angle), s = std::sin(angle);
        Bounds bounds;
        for (const Vec2 v : chain->points) bounds.add(p->value + Vec2{c * v.x - s * v.y, s * v.x + c * v.y});
        return ShapeBox{0.5 * (bounds.lo + bounds.hi), 0.5 * (bounds.hi - bounds.lo)};
    }
    return std::nullopt;
}

bool isStatic(const Scene& scene, Entity e) {
    const Static* s = scene.registry.tryGet<Static>(e);
    return s && s->value;
}

} // namespace stepwise::render
