// The viewport camera (editor/app/view_camera).

#include "editor_fixture.hpp"

using namespace stepwise;
using namespace stepwise::editor;
using namespace stepwise::editor_test;
using stepwise::test::readFile;

TEST(Camera, ZoomKeepsThePointUnderTheCursor) {
    ViewCamera v;
    v.width = 640;
    v.height = 480;
    v.camera.center = {1.0, 2.0};
    const Vec2 cursor{100.0, 400.0};
    const Vec2 before = v.toWorld(cursor);
    v.zoomAt(cursor, 3.0);
    const Vec2 after = v.toWorld(cursor);
    EXPECT_NEAR(before.x, after.x, 1e-9);
    EXPECT_NEAR(before.y, after.y, 1e-9);
    const Vec2 round = v.toWorld(v.toPixels({-3.0, 7.5}));
    EXPECT_NEAR(round.x, -3.0, 1e-9);
    EXPECT_NEAR(round.y, 7.5, 1e-9);
}
