// When an adaptive geometry trial stops (AdaptiveTrialJudge, coding/geometry/level_geometry.h):
// the exact limit always; the sample's projections (from its first eighth on, the first two only
// from rates over enough committed bytes), and past the sample one more projection at the end of
// every further sample's length. A trial that wins leaves the level's payload coded.
#include "coding/geometry/geometry_prediction.h"
#include "coding/geometry/level_geometry.h"

#include <amc/hierarchy.h>
#include <amc/refinement.h>

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <functional>

namespace amc {
namespace {

// The first vertex count after which the judge stops a trial whose code has committed
// bytes(done) bytes after `done` vertices, or 0 if it runs to the level's end.
size_t stopped_at(size_t count, size_t sample, size_t limit, const std::function<size_t(size_t)>& bytes) {
    AdaptiveTrialJudge judge(count, sample, limit);
    for (size_t done = 1; done <= count; ++done)
        if (judge.stops(done, bytes(done))) return done;
    return 0;
}

// 0.1 bytes a vertex for the first `switch_at` vertices, then `later` a vertex.
std::function<size_t(size_t)> two_rates(size_t switch_at, double later) {
    return [=](size_t done) {
        const double first = 0.1 * double(std::min(done, switch_at));
        return size_t(first + later * double(done > switch_at ? done - switch_at : 0));
    };
}

TEST(AdaptiveTrial, RunsOnWhileItsProjectionStaysBelowTheLimit) {
    // 819 bytes for the level against a limit of 1,000: every projection says it may win.
    EXPECT_EQ(stopped_at(8192, 1024, 1000, two_rates(8192, 0.0)), 0u);
}

TEST(AdaptiveTrial, StopsAtTheEndOfTheSampleLengthWhereItsRateRose) {
    // The sample projects 816 bytes; from there the rate doubles, and the end of the next
    // sample's length projects 1,536 bytes, past 1.125 times the limit and the slack: the trial
    // stops there, not at 5,557 vertices where its bytes pass the limit.
    EXPECT_EQ(stopped_at(8192, 1024, 1000, two_rates(1024, 0.2)), 2048u);
    // The rate rises late: the test after it stops the trial.
    EXPECT_EQ(stopped_at(8192, 1024, 1000, two_rates(3500, 0.4)), 4096u);
}

TEST(AdaptiveTrial, WithoutASampleOnlyTheLimitStopsIt) {
    // The same bytes: they pass the limit by more than 8 bytes after 5,557 vertices.
    EXPECT_EQ(stopped_at(8192, SIZE_MAX, 1000, two_rates(1024, 0.2)), 5557u);
    EXPECT_EQ(stopped_at(8192, SIZE_MAX, 1000, two_rates(8192, 0.0)), 0u);
}

TEST(AdaptiveTrial, HalfwayThroughTheSampleALargeRateStopsIt) {
    // 0.4 bytes a vertex from vertex 256 on: halfway (512) the projection is 3,098 bytes, past
    // 1.25 times the limit.
    EXPECT_EQ(stopped_at(8192, 1024, 1000, [](size_t done) { return done <= 256 ? done / 10 : 25 + (done - 256) * 2 / 5; }), 512u);
}

TEST(AdaptiveTrial, AfterTheSamplesFirstEighthALargeRateStopsIt) {
    // 0.4 bytes a vertex from the start: after 128 vertices (an eighth of the sample) the rate of
    // the sixteenth before rests on 26 bytes and projects 3,327 bytes, past 1.25 times the limit.
    EXPECT_EQ(stopped_at(8192, 1024, 1000, [](size_t done) { return done * 2 / 5; }), 128u);
}

TEST(AdaptiveTrial, AnEarlyRateFromFewCommittedBytesDoesNotStopIt) {
    // 0.1 bytes a vertex for the first 256 vertices, then none: the first eighth's and quarter's
    // rates (6 and 13 committed bytes) would project 768 and 831 bytes against a limit of 100,
    // but rest on too few bytes; halfway the rate is 0, and the level codes in 25 bytes.
    EXPECT_EQ(stopped_at(8192, 1024, 100, two_rates(256, 0.0)), 0u);
}

// choose_level_geometry with the level block's code (its hierarchy part) codes an adaptive trial
// that looks like winning onto it as it goes, from the sample's end on (the vertices before again)
// or, without a sample, from the first eighth's: the payloads and the models after each level must
// be those of coding the level again in finish_level_payload. Exact midpoints (the corpus's uniform
// model): the adaptive midpoint wins the small levels and the last, the only one it looks like
// winning early, mode 3 those between.
TEST(AdaptiveTrial, AWinningTrialsCodingIsTheLevelsPayload) {
    Hierarchy h(make_icosahedron());
    refine_uniformly(h, 7);  // the last level's 122,880 new vertices are judged on a sample at effort 1
    for (int effort : {1, kMaxEffort}) {
        SCOPED_TRACE("effort " + std::to_string(effort));
        const CoordinateSpace space;  // float64, bit-exact: raw bits in the side stream
        PositionCoder again_models(space), taken_models(space);
        int taken = 0, sampled = 0;
        for (const std::vector<NodeId>& level : nodes_by_level(h)) {
            const NewVertices created = new_vertices_of_level(h, level);
            if (created.empty()) continue;
            ArithmeticEncoder hierarchy_part;  // stands for the level's hierarchy symbols
            BitModel model;
            for (size_t i = 0; i < level.size(); ++i) hierarchy_part.encode(i % 3 == 0, model);
            ArithmeticEncoder again_encoder = hierarchy_part, taken_encoder = hierarchy_part;
            LevelGeometryCode again = choose_level_geometry(h, created, again_models, space, GeometryPredictor::automatic, false,
                                                            true, effort);
            LevelGeometryCode code = choose_level_geometry(h, created, taken_models, space, GeometryPredictor::automatic, false, true,
                                                           effort, StaticOrder::grouped, nullptr, &taken_encoder);
            EXPECT_EQ(again.adaptive_code, nullptr);
            ASSERT_EQ(code.predictor, again.predictor);
            EXPECT_TRUE(code.adaptive_code == nullptr || !is_static_mode(code.predictor));
            taken += code.adaptive_code != nullptr;
            sampled += code.adaptive_code != nullptr && created.size() >= 2048;
            EXPECT_EQ(finish_level_payload(h, created, code, taken_models, taken_encoder),
                      finish_level_payload(h, created, again, again_models, again_encoder))
                << created.size() << " new vertices";
        }
        EXPECT_EQ(taken, 1);
        EXPECT_EQ(sampled, 1);
    }
}

}  // namespace
}  // namespace amc
