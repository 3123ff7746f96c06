// Registry: generational handles, sparse-set pools, views over the
// smallest pool, deep copies.

#include "stepwise/components.hpp"
#include "stepwise/registry.hpp"

#include <gtest/gtest.h>

#include <vector>

using namespace stepwise;

TEST(Registry, CreatedEntitiesAreAliveAndDistinct) {
    Registry r;
    const Entity a = r.create();
    const Entity b = r.create();
    EXPECT_TRUE(r.alive(a));
    EXPECT_TRUE(r.alive(b));
    EXPECT_NE(a, b);
    EXPECT_EQ(r.size(), 2u);
    EXPECT_EQ(r.entities(), (std::vector<Entity>{a, b}));
}

TEST(Registry, StaleHandleIsDetectedAfterSlotReuse) {
    Registry r;
    const Entity a = r.create();
    r.emplace<Mass>(a, Mass{3.0});
    ASSERT_TRUE(r.destroy(a));
    EXPECT_FALSE(r.alive(a));
    // The slot is reused with a new generation: the old handle stays stale.
    const Entity b = r.create();
    EXPECT_EQ(b.index, a.index);
    EXPECT_EQ(b.generation, a.generation + 1);
    EXPECT_FALSE(r.alive(a));
    EXPECT_EQ(r.tryGet<Mass>(a), nullptr);
    EXPECT_EQ(r.tryGet<Mass>(b), nullptr) << "components of the destroyed entity must not leak to the new one";
    EXPECT_FALSE(r.destroy(a)) << "destroying through a stale handle is a soft failure";
    EXPECT_TRUE(r.alive(b));
    EXPECT_FALSE(r.remove<Mass>(a));
}

TEST(Registry, NullHandleIsNeverAlive) {
    Registry r;
    r.create();
    EXPECT_FALSE(r.alive(Entity{}));
    EXPECT_TRUE(Entity{}.isNull());
}

TEST(Registry, EmplaceReplacesAndRemoveReports) {
    Registry r;
    const Entity e = r.create();
    r.emplace<Mass>(e, Mass{2.0});
    r.emplace<Mass>(e, Mass{5.0});
    ASSERT_NE(r.tryGet<Mass>(e), nullptr);
    EXPECT_EQ(r.tryGet<Mass>(e)->value, 5.0);
    EXPECT_EQ(r.count<Mass>(), 1u);
    EXPECT_TRUE(r.remove<Mass>(e));
    EXPECT_FALSE(r.remove<Mass>(e));
    EXPECT_FALSE(r.has<Mass>(e));
}

TEST(Registry, EachVisitsOnlyEntitiesWithEveryComponent) {
    Registry r;
    std::vector<Entity> both;
    for (int i = 0; i < 10; ++i) {
        const Entity e = r.create();
        r.emplace<Position>(e, Position{{double(i), 0.0}});
        if (i % 3 == 0) {
            r.emplace<Velocity>(e, Velocity{{1.0, double(i)}});
            both.push_back(e);
        }
    }
    std::vector<Entity> seen;
    double sum = 0.0;
    r.each<Position, Velocity>([&](Entity e, Position& p, Velocity& v) {
        seen.push_back(e);
        sum += p.value.x + v.value.y;
    });
    EXPECT_EQ(seen, both);
    EXPECT_EQ(sum, 2.0 * (0 + 3 + 6 + 9));
    int none = 0;
    r.each<Position, Spring>([&](Entity, Position&, Spring&) { ++none; });
    EXPECT_EQ(none, 0) << "a pool that was never created means no matches";
}

TEST(Registry, SwapRemoveKeepsOtherComponentsIntact) {
    Registry r;
    std::vector<Entity> es;
    for (int i = 0; i < 5; ++i) {
        es.push_back(r.create());
        r.emplace<Mass>(es.back(), Mass{double(i + 1)});
    }
    r.destroy(es[1]);
    r.remove<Mass>(es[3]);
    EXPECT_EQ(r.tryGet<Mass>(es[0])->value, 1.0);
    EXPECT_EQ(r.tryGet<Mass>(es[2])->value, 3.0);
    EXPECT_EQ(r.tryGet<Mass>(es[4])->value, 5.0);
    EXPECT_EQ(r.count<Mass>(), 3u);
    EXPECT_EQ(r.entities(), (std::vector<Entity>{es[0], es[2], es[3], es[4]}));
}

TEST(Registry, CopyIsDeep) {
    Registry r;
    const Entity e = r.create();
    r.emplace<Name>(e, Name{"ball"});
    Registry copy = r;
    copy.tryGet<Name>(e)->value = "changed";
    EXPECT_EQ(r.tryGet<Name>(e)->value, "ball");
    EXPECT_EQ(copy.tryGet<Name>(e)->value, "changed");
    copy.destroy(e);
    EXPECT_TRUE(r.alive(e));
}

TEST(Registry, ReorderMovesWithinSceneOrder) {
    Registry r;
    const Entity a = r.create(), b = r.create(), c = r.create();
    r.reorder(c, 0);
    EXPECT_EQ(r.entities(), (std::vector<Entity>{c, a, b}));
}
