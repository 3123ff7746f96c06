#include "camera.hpp"

#include "scene_bounds.hpp"

#include "stepwise/components.hpp"

#include <algorithm>

namespace stepwise::render {

Camera fitCamera(const Scene& scene, int widthPx, int heightPx) {
    Bounds b;
    const Registry& reg = scene.registry;
    for (Entity e : reg.entities()) {
        if (const Position* p = reg.tryGet<Position>(e)) {
            if (reg.has<Spring>(e)) continue;
            if (const auto shape = shapeBox(scene, e)) {
                b.add(shape->centre - shape->half);
                b.add(shape->centre + shape->half);
            } else {
                b.add(p->value, 0.25);
            }
        }
        if (const Spring* s = reg.tryGet<Spring>(e); s && s->anchor) b.add(*s->anchor, 0.25);
    }
    // Planes are infinite: show the part nearest the rest of the scene, and
    // a metre of the solid side so the hatching reads.
    const Vec2 middle = b.empty() ? Vec2{} : 0.5 * (b.lo + b.hi);
    reg.each<Plane>([&](Entity, const Plane& p) {
        const Vec2 q = middle - (dot(p.normal, middle) - p.offset) * p.normal;
        b.add(q - p.normal * 1.0);
        b.add(q);
    });
    Camera cam;
    if (b.empty()) return cam;
    const Vec2 size{std::max(b.hi.x - b.lo.x, 2.0), std::max(b.hi.y - b.lo.y, 2.0)};
    cam.center = 0.5 * (b.lo + b.hi);
    // 12% margin each side.
    const double ppm = std::min(double(widthPx) / (size.x * 1.24), double(heightPx) / (size.y * 1.24));
    cam.zoom = ppm * 720.0 / double(heightPx);
    return cam;
}

Camera sceneCamera(const Scene& scene, int widthPx, int heightPx) {
    if (scene.view) return Camera{scene.view->center, scene.view->zoom};
    return fitCamera(scene, widthPx, heightPx);
}

} // namespace stepwise::render
